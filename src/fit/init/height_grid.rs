//! [`InitKind::Open`](super::InitKind::Open): an open quad grid over a single
//! range view.
//!
//! The points are expressed in their principal frame `(u, v, w)` — `u, v` on
//! the plane of the two largest axes, `w` along the third. A grid of square
//! cells of side `h = max(ext_u, ext_v) / resolution` covers the `(u, v)`
//! bounding box; the cells holding points, repaired by [`footprint`], become
//! the quads. The height of grid vertex `(u_i, v_j)` comes from the points in
//! its four cells (a `2h × 2h` window): a least-squares plane
//! `w ≈ a + b (u − u_i) + c (v − v_j)`, refitted once without the points whose
//! residual exceeds three robust standard deviations (outliers, the far side
//! of a depth jump), evaluated at the vertex, `w = a`, and clamped to the
//! range of the kept points' heights (no wild extrapolation where the window
//! holds a steep patch). A plane is exact on slopes, so rim vertices, whose
//! window holds points on one side only, are not biased the way a mean or
//! median would be. Windows with fewer than six
//! points or a degenerate plane take the median; vertices without points take
//! the mean of their grid neighbours' heights, repeatedly (harmonic fill).
//!
//! Orientation: faces are counter-clockwise in `(u, v)`, so their normals
//! point along `+w`, and `+w` is chosen to face the scanner. When the cloud
//! has normals, `+w` is the side most normals point to. Range scans such as
//! Stanford's `bun045.ply` carry none; then `+w` is the side the surface bulges
//! towards — a single view of a solid sees a cap whose middle is nearer the
//! scanner than its rim — measured by the sign of `Σ w (r² − mean r²)` with
//! `r² = u² + v²`: negative (the rim lies further along `−w` than the middle)
//! keeps the PCA sign, positive turns the frame half a turn about `a_0`.

use super::footprint::{FootprintStats, footprint};
use super::frame::PrincipalFrame;
use crate::error::{Error, Result};
use crate::math::{Real, Vector3, group_by_key};
use crate::mesh::PointCloud;
use crate::mesh::PolyMesh;

/// The open cage and how it was built.
#[derive(Clone, Debug)]
pub struct HeightGrid {
    /// The quad grid, normals along `+w` of [`HeightGrid::frame`].
    pub mesh: PolyMesh,
    /// The frame used, with `a_2 = +w` towards the scanner.
    pub frame: PrincipalFrame,
    /// Grid cells along `u` and `v`.
    pub cells: (usize, usize),
    /// What the footprint repair did.
    pub stats: FootprintStats,
    /// "normals" or "bulge": which rule chose the side.
    pub side_rule: &'static str,
}

/// Picks the sign of the third axis so that `+w` faces the scanner (module docs).
pub fn scanner_side(cloud: &PointCloud, frame: &PrincipalFrame) -> (PrincipalFrame, &'static str) {
    if let Some(normals) = &cloud.normals {
        let s: Real = normals
            .iter()
            .filter(|n| n.iter().all(|c| c.is_finite()))
            .map(|n| n.dot(&frame.axes[2]).signum())
            .sum();
        if s != 0.0 {
            return (
                if s > 0.0 {
                    frame.clone()
                } else {
                    frame.flipped()
                },
                "normals",
            );
        }
    }
    let local: Vec<Vector3> = cloud.positions.iter().map(|p| frame.local(p)).collect();
    let r2 = |l: &Vector3| l[0] * l[0] + l[1] * l[1];
    let mean_r2 = local.iter().map(r2).sum::<Real>() / local.len() as Real;
    let s: Real = local.iter().map(|l| l[2] * (r2(l) - mean_r2)).sum();
    (
        if s <= 0.0 {
            frame.clone()
        } else {
            frame.flipped()
        },
        "bulge",
    )
}

/// The open grid cage of a single range view (module docs).
pub fn height_grid(
    cloud: &PointCloud,
    frame: &PrincipalFrame,
    resolution: usize,
    min_cell_points: usize,
) -> Result<HeightGrid> {
    let (frame, side_rule) = scanner_side(cloud, frame);
    let ext = frame.extents();
    let h = ext[0].max(ext[1]) / resolution as Real;
    let cells_along = |e: Real| ((e / h - 1e-9).ceil() as usize).clamp(1, resolution);
    let (nu, nv) = (cells_along(ext[0]), cells_along(ext[1]));
    let (u0, v0) = (frame.lo[0], frame.lo[1]);
    let cell_of = |l: &Vector3| -> usize {
        let i = (((l[0] - u0) / h).floor().max(0.0) as usize).min(nu - 1);
        let j = (((l[1] - v0) / h).floor().max(0.0) as usize).min(nv - 1);
        i + nu * j
    };
    // Counting sort of the points' heights by cell (CSR).
    let local: Vec<Vector3> = cloud.positions.iter().map(|p| frame.local(p)).collect();
    let (offsets, sorted) = group_by_key(nu * nv, local.iter().map(|l| (cell_of(l), *l)));
    let counts: Vec<usize> = offsets.windows(2).map(|w| w[1] - w[0]).collect();
    let (mask, stats) = footprint(nu, nv, &counts, min_cell_points);
    // Grid vertices used by kept cells, and their median heights.
    let (gu, gv) = (nu + 1, nv + 1);
    let mut used = vec![false; gu * gv];
    for j in 0..nv {
        for i in 0..nu {
            if mask.kept[i + nu * j] {
                for (a, b) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                    used[i + a + gu * (j + b)] = true;
                }
            }
        }
    }
    let mut height: Vec<Option<Real>> = vec![None; gu * gv];
    let mut window = Vec::new();
    for j in 0..gv {
        for i in 0..gu {
            if !used[i + gu * j] {
                continue;
            }
            window.clear();
            for cj in j.saturating_sub(1)..(j + 1).min(nv) {
                for ci in i.saturating_sub(1)..(i + 1).min(nu) {
                    let c = ci + nu * cj;
                    window.extend_from_slice(&sorted[offsets[c]..offsets[c + 1]]);
                }
            }
            let at = (u0 + i as Real * h, v0 + j as Real * h);
            height[i + gu * j] = window_height(&window, at);
        }
    }
    harmonic_fill(&mut height, &used, gu, gv);
    // Compact vertex numbering and quads counter-clockwise in (u, v).
    let mut id = vec![u32::MAX; gu * gv];
    let mut positions = Vec::new();
    for j in 0..gv {
        for i in 0..gu {
            let g = i + gu * j;
            if used[g] {
                id[g] = positions.len() as u32;
                let w = height[g].unwrap_or(0.0);
                positions.push(frame.world(&Vector3::new(
                    u0 + i as Real * h,
                    v0 + j as Real * h,
                    w,
                )));
            }
        }
    }
    let mut faces = Vec::with_capacity(mask.count());
    for j in 0..nv {
        for i in 0..nu {
            if mask.kept[i + nu * j] {
                let g = |a: usize, b: usize| id[i + a + gu * (j + b)];
                faces.push(vec![g(0, 0), g(1, 0), g(1, 1), g(0, 1)]);
            }
        }
    }
    if faces.is_empty() {
        return Err(Error::input(
            "no grid cell holds enough points for an open initial model",
        ));
    }
    let mesh = PolyMesh::from_faces(positions, &faces)?;
    Ok(HeightGrid {
        mesh,
        frame,
        cells: (nu, nv),
        stats,
        side_rule,
    })
}

/// Height at `at = (u, v)` from the window's points: trimmed least-squares
/// plane, or the median when the plane is not determined (module docs).
fn window_height(window: &[Vector3], at: (Real, Real)) -> Option<Real> {
    let fit = |pts: &[&Vector3]| -> Option<[Real; 3]> {
        if pts.len() < 6 {
            return None;
        }
        let mut a = nalgebra::Matrix3::<Real>::zeros();
        let mut b = Vector3::zeros();
        for p in pts {
            let x = Vector3::new(1.0, p[0] - at.0, p[1] - at.1);
            a += x * x.transpose();
            b += x * p[2];
        }
        // Degenerate when the points are (nearly) on a line in (u, v).
        if a.determinant().abs() <= 1e-12 * a.norm().powi(3) {
            return None;
        }
        a.lu().solve(&b).map(|s| [s[0], s[1], s[2]])
    };
    let all: Vec<&Vector3> = window.iter().collect();
    let Some(c) = fit(&all) else {
        let mut w: Vec<Real> = window.iter().map(|p| p[2]).collect();
        return median(&mut w);
    };
    let residual = |p: &Vector3| p[2] - (c[0] + c[1] * (p[0] - at.0) + c[2] * (p[1] - at.1));
    let mut abs: Vec<Real> = all.iter().map(|p| residual(p).abs()).collect();
    let sigma = 1.4826 * median(&mut abs).unwrap_or(0.0);
    if sigma <= 0.0 {
        // Exactly planar window: the fit is exact.
        return Some(c[0]);
    }
    let kept: Vec<&Vector3> = all
        .into_iter()
        .filter(|p| residual(p).abs() <= 3.0 * sigma)
        .collect();
    let (lo, hi) = kept
        .iter()
        .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[2]), hi.max(p[2]))
        });
    let w = fit(&kept).map_or(c[0], |c2| c2[0]);
    Some(if lo <= hi { w.clamp(lo, hi) } else { w })
}

/// Median of `values` (mean of the middle two for an even count); `None` when empty.
fn median(values: &mut [Real]) -> Option<Real> {
    if values.is_empty() {
        return None;
    }
    values.sort_unstable_by(|a, b| a.total_cmp(b));
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

/// Gives every used vertex without a height the mean of its known 4-neighbours,
/// sweep after sweep; each sweep fixes at least one vertex adjacent to a known
/// one, so at most `gu·gv` sweeps run (vertices never reached keep `None`).
fn harmonic_fill(height: &mut [Option<Real>], used: &[bool], gu: usize, gv: usize) {
    loop {
        let mut changed = false;
        let snapshot = height.to_vec();
        for j in 0..gv {
            for i in 0..gu {
                let g = i + gu * j;
                if !used[g] || snapshot[g].is_some() {
                    continue;
                }
                let mut sum = 0.0;
                let mut n = 0;
                for (di, dj) in [(1isize, 0isize), (-1, 0), (0, 1), (0, -1)] {
                    let (x, y) = (i as isize + di, j as isize + dj);
                    if x >= 0
                        && y >= 0
                        && (x as usize) < gu
                        && (y as usize) < gv
                        && let Some(w) = snapshot[x as usize + gu * y as usize]
                    {
                        sum += w;
                        n += 1;
                    }
                }
                if n > 0 {
                    height[g] = Some(sum / n as Real);
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
}
