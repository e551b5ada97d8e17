//! Which control faces to refine: those whose data residual is above the
//! noise (the test behind adaptive refinement in
//! [`Refinement::Adaptive`](super::Refinement)), and those with a surface
//! sample far off the data ([`faces_off_data`]).
//!
//! With Gaussian noise of deviation `σ` along the normal, the squared
//! distances of a face's `n` points to a surface that has no bias there
//! average `σ²` with standard error `σ² √(2/n)` (a `χ²ₙ/n` variable). A face
//! is refined when its mean squared distance exceeds `σ̂² (1 + z √(2/n))`:
//! the surface misses a shape the data show there, which a finer control
//! mesh can follow. `σ̂ = median |d| / 0.6745` over every point with a
//! non-zero robust weight (the median of a half-normal variable is
//! `0.6745 σ`); where more than half of the points are fitted to within
//! the noise this estimates the noise, otherwise it overestimates it and the
//! test refines fewer faces, to be tested again at the next level.

use crate::math::Real;

/// Fewer points than this on a face give no evidence for refining it.
pub const MIN_POINTS: usize = 4;

/// The faces to refine and the noise estimate `σ̂` they were judged by.
/// `face[i]` is the control face holding point `i`'s closest point, `dist[i]`
/// its distance and `weight[i]` its robust weight (0 = outlier, not counted).
pub fn faces_above_noise(
    num_faces: usize,
    face: &[u32],
    dist: &[Real],
    weight: &[Real],
    data_noise: Real,
    z: Real,
) -> (Vec<bool>, Real) {
    let mut inliers: Vec<Real> = dist
        .iter()
        .zip(weight)
        .filter(|(d, w)| **w > 0.0 && d.is_finite())
        .map(|(d, _)| *d)
        .collect();
    if inliers.is_empty() {
        return (vec![false; num_faces], 0.0);
    }
    let mid = inliers.len() / 2;
    let median = *inliers.select_nth_unstable_by(mid, Real::total_cmp).1;
    let sigma = (median / 0.6745).min(data_noise);
    let marks = face_residuals(num_faces, face, dist, weight)
        .iter()
        .map(|&(n, ms)| {
            n >= MIN_POINTS && ms > sigma * sigma * (1.0 + z * (2.0 / n as Real).sqrt())
        })
        .collect();
    (marks, sigma)
}

/// Per control face: the number of counted points (non-zero `weight`,
/// finite `dist`) whose closest point is on it, and their mean squared
/// distance (0 without points); arguments as in [`faces_above_noise`].
pub fn face_residuals(
    num_faces: usize,
    face: &[u32],
    dist: &[Real],
    weight: &[Real],
) -> Vec<(usize, Real)> {
    let mut out = vec![(0usize, 0.0); num_faces];
    for ((&f, &d), &w) in face.iter().zip(dist).zip(weight) {
        if w > 0.0 && d.is_finite() {
            out[f as usize].0 += 1;
            out[f as usize].1 += d * d;
        }
    }
    for (n, s) in &mut out {
        *s /= (*n).max(1) as Real;
    }
    out
}

/// The faces holding a surface sample whose distance to its nearest data
/// point exceeds `factor` times the median of those distances: parts of the
/// surface spanning a gap in the data (a web across a slot the scan did not
/// see into). No data point is closest to such a face, so
/// [`faces_above_noise`] never splits it. The median measures the data's
/// spacing and noise, which every sample of a surface that follows the data
/// is within. `face[i]` is the control face of sample `i`; `factor` ≤ 0
/// marks nothing.
pub fn faces_off_data(num_faces: usize, face: &[u32], dist: &[Real], factor: Real) -> Vec<bool> {
    let mut marks = vec![false; num_faces];
    let mut finite: Vec<Real> = dist.iter().copied().filter(|d| d.is_finite()).collect();
    if factor <= 0.0 || finite.is_empty() {
        return marks;
    }
    let mid = finite.len() / 2;
    let limit = factor * *finite.select_nth_unstable_by(mid, Real::total_cmp).1;
    for (&f, &d) in face.iter().zip(dist) {
        if d > limit {
            marks[f as usize] = true;
        }
    }
    marks
}
