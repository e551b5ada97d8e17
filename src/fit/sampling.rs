//! What the fitting driver samples: an even shuffle of the data points
//! (coarse levels use a prefix), the surface samples of the surface-to-data
//! springs, and the outlier-robust RMS of its stall test.

use crate::limit::PatchTable;
use crate::math::Real;

/// `0..n` in a fixed pseudo-random order (a multiplicative hash of the
/// index), so that every prefix is an even subsample of a cloud.
pub(super) fn shuffled_order(n: usize) -> Vec<usize> {
    let mut order: Vec<(u64, usize)> = (0..n)
        .map(|i| {
            (
                (i as u64 + 1)
                    .wrapping_mul(0x9E37_79B9_7F4A_7C15)
                    .rotate_left(29),
                i,
            )
        })
        .collect();
    order.sort_unstable();
    order.into_iter().map(|(_, i)| i).collect()
}

/// `per_side × per_side` cell centres of every patch of `table`, as
/// (patch, `(s, t)`): where the surface-to-data springs attach.
pub(super) fn surface_samples(table: &PatchTable, per_side: usize) -> Vec<(usize, [Real; 2])> {
    let cell = |k: usize| (k as Real + 0.5) / per_side as Real;
    (0..table.num_patches())
        .flat_map(|f| {
            (0..per_side * per_side).map(move |i| (f, [cell(i % per_side), cell(i / per_side)]))
        })
        .collect()
}

/// Root mean square of the smallest `fraction` of `d`.
pub(super) fn trimmed_rms(d: &[Real], fraction: Real) -> Real {
    let mut sorted = d.to_vec();
    let keep = ((fraction * d.len() as Real).ceil() as usize).clamp(1, d.len().max(1));
    if sorted.is_empty() {
        return 0.0;
    }
    sorted.select_nth_unstable_by(keep - 1, |a, b| a.total_cmp(b));
    (sorted[..keep].iter().map(|x| x * x).sum::<Real>() / keep as Real).sqrt()
}
