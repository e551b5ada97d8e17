//! Carving the occupancy with the points' signed distance: opens gaps the
//! shell's dilation bridged.
//!
//! The occupancy shell marks every voxel a sampling ball touches, so two
//! surfaces closer than about two voxels (a quadruped's legs, fingers) end
//! up in one solid and the cage joins them with a web no fit can remove:
//! the genus and the sheet structure of a cage are fixed. The oriented
//! tangent planes of the points ([`super::normals`], Hoppe et al. 1992)
//! tell inside from outside at sub-voxel scale. A solid voxel is removed
//! when
//!
//! - its centre lies between two sheets of surface facing each other within
//!   two voxels ([`SignedDistance::between_sheets`]): a web spans free
//!   space there, whereas the outside of a lone thin part (a horn) faces
//!   one sheet only, and far from the points the planes are extrapolations
//!   that decide nothing; and
//! - of its 3 × 3 × 3 sub-cell centres, fewer than a quarter are inside
//!   (signed distance ≤ 0), or none at all when the voxel holds points. A
//!   gap at least 1.5 voxels wide always contains a voxel three-quarters
//!   outside. The stricter rule for voxels holding points keeps a part
//!   thinner than a voxel that runs through them; a voxel at the side of a
//!   gap that catches a few noisy points of the wall is still all outside.
//!   A voxel whose points all have its centre on the outer side of their
//!   tangent planes (the walls of a gap it spans, nothing running through
//!   it) and that the quarter rule puts outside is returned as a *wall*
//!   instead: a slot or hole under two voxels wide is often bridged by such
//!   voxels (the plate's slot, 1.75 voxels, by voxels with 1 to 6 of 27
//!   sub-cells inside), but removing them also cuts dents into a surface,
//!   which can open a false handle ([`super::occupancy`] builds the cage
//!   both ways).
//!
//! Carving trusts the normals' orientation, so it first checks them
//! against the flood fill: a point's normal should lead to an outside
//! voxel (`p + 1.5 h n`) rather than away from one (`p − 1.5 h n`).
//! Unless at least [`MIN_AGREEMENT`] of the points that reach the outside
//! one way or the other agree, nothing is carved.

use rayon::prelude::*;

use super::normals::SignedDistance;
use super::voxels::VoxelGrid;
use crate::math::{Point3, Real};

/// Sub-samples per voxel axis.
const SUB: usize = 3;

/// A voxel is removed when fewer than this fraction of its sub-samples are inside.
const INSIDE_FRACTION: Real = 0.25;

/// Fraction of decided points whose normals must lead outwards.
pub const MIN_AGREEMENT: Real = 0.9;

/// The points a voxel holds, seen from its centre.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Held {
    /// None.
    Empty,
    /// All of them have the centre on the outer side of their tangent
    /// planes: the walls of a gap the voxel spans, or of a dent.
    Facing,
    /// Some have it on the inner side: a part may run through the voxel.
    Within,
}

/// What [`carve`] did, and the gap walls it left.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Carving {
    /// What was removed.
    pub stats: CarveStats,
    /// Voxels the quarter rule puts outside but left because they hold
    /// points (all with the voxel's centre on their outer side): the walls
    /// of a gap, or of a dent (module docs).
    pub walls: Vec<usize>,
}

/// What [`carve`] removed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CarveStats {
    /// Fraction of the points deciding the orientation check that agreed.
    pub agreement: Real,
    /// Voxels removed (0 when the check failed).
    pub removed: usize,
}

/// Removes the solid voxels of `solid` the signed distance puts outside
/// (module docs). `world(x)` maps continuous grid coordinates (voxel `v`
/// spans `v .. v + 1`) to space, `voxel_of(p)` maps a point to its voxel;
/// `h` is the voxel side.
pub fn carve(
    solid: &mut VoxelGrid,
    sd: &SignedDistance,
    h: Real,
    world: impl Fn([Real; 3]) -> Point3 + Sync,
    voxel_of: impl Fn(&Point3) -> Option<usize>,
) -> Carving {
    let outside = solid.outside();
    let is_out = |p: Point3| voxel_of(&p).is_none_or(|n| outside[n]);
    let mut held = vec![Held::Empty; solid.solid.len()];
    let (mut agree, mut disagree) = (0usize, 0usize);
    for (p, n) in sd.oriented_points() {
        if let Some(v) = voxel_of(p) {
            let c = solid.coords(v).map(|x| x as Real + 0.5);
            let outer = (world(c) - p).dot(n) > 0.0;
            held[v] = match (held[v], outer) {
                (Held::Empty | Held::Facing, true) => Held::Facing,
                _ => Held::Within,
            };
        }
        let (ahead, behind) = (is_out(p + n * (1.5 * h)), is_out(p - n * (1.5 * h)));
        match (ahead, behind) {
            (true, false) => agree += 1,
            (false, true) => disagree += 1,
            _ => {}
        }
    }
    let agreement = agree as Real / (agree + disagree).max(1) as Real;
    if agreement < MIN_AGREEMENT {
        return Carving {
            stats: CarveStats {
                agreement,
                removed: 0,
            },
            walls: Vec::new(),
        };
    }
    let verdicts: Vec<(usize, bool)> = (0..solid.solid.len())
        .into_par_iter()
        .filter(|&n| solid.solid[n])
        .filter_map(|n| {
            let c = solid.coords(n).map(|x| x as Real);
            if !sd.between_sheets(&world([c[0] + 0.5, c[1] + 0.5, c[2] + 0.5]), 2.0 * h) {
                return None;
            }
            let mut inside = 0;
            for k in 0..SUB * SUB * SUB {
                let s = [k % SUB, (k / SUB) % SUB, k / (SUB * SUB)]
                    .map(|i| (i as Real + 0.5) / SUB as Real);
                let (d, _) = sd.at(&world([c[0] + s[0], c[1] + s[1], c[2] + s[2]]));
                inside += usize::from(d <= 0.0);
            }
            let mostly_outside = (inside as Real) < INSIDE_FRACTION * (SUB * SUB * SUB) as Real;
            match held[n] {
                _ if inside == 0 => Some((n, true)),
                Held::Empty if mostly_outside => Some((n, true)),
                Held::Facing if mostly_outside => Some((n, false)),
                _ => None,
            }
        })
        .collect();
    let mut removed = 0;
    let mut walls = Vec::new();
    for (n, outside) in verdicts {
        if outside {
            solid.solid[n] = false;
            removed += 1;
        } else {
            walls.push(n);
        }
    }
    Carving {
        stats: CarveStats { agreement, removed },
        walls,
    }
}
