//! [`InitKind::Occupancy`](super::InitKind::Occupancy): a closed quad cage of
//! any genus from the points' voxel occupancy.
//!
//! Qin, Mandal and Vemuri (1998) leave the initial model to the user; for
//! shapes of higher genus a sphere-like start cannot change topology, so the
//! cage must already have the right genus. Steps, all on a grid aligned with
//! the principal axes, `resolution` voxels of side `h` along the longest
//! extent plus a 6-voxel margin on each side. When the points have narrow
//! gaps between facing sheets ([`narrow_gap`]), `h` shrinks to two-thirds of
//! the gap, down to `1 / max_refinement` of that voxel, so carving can open
//! them:
//!
//! 1. *shell*: every voxel that meets a ball of radius `r` around a point,
//!    `r` the sampling radius ([`sampling_radius`], clamped to `[h/100, 2h]`).
//!    The balls cover the sampled surface, so every voxel the surface crosses
//!    is marked and the shell has no gap a face-connected path of empty voxels
//!    could pass through — a dilation by the sampling density rather than by
//!    a whole voxel, so holes of the object wider than about `2h + 2r` (3 to
//!    4 voxels for dense clouds) survive;
//! 2. *fill*: flood the outside from the grid border through face
//!    neighbours; `solid = not outside`. A scan with unseen regions (few
//!    views) leaves holes in the shell and the flood leaks inside. The leak is
//!    measured with [`interior_probes`] — points midway between the first two
//!    sheets of surface met along the principal axes, which must be inside —
//!    and when more than a quarter of them are outside, the fill is redone
//!    as a *closing* by `k = 1, 2, 3` cubes ([`VoxelGrid::closed_solid`]:
//!    dilate `k` times, fill, erode `k` times), which closes shell gaps up to
//!    `2k` voxels wide (and holes of the object as narrow). The smallest `k`
//!    that repairs the leak is taken: at most a quarter of the probes
//!    outside, and at most a quarter as many as with the plain fill. When no
//!    closing repairs it, the probes were not inside: a line through two
//!    separate thin parts (a chair's legs, the slats of its back) meets each
//!    as one sheet and the "interior" between them is free space, which
//!    closings fill a little more with each `k` — webs, not a repair — so
//!    the plain fill stands;
//! 3. *carve* ([`carve`]): voxels the points' oriented tangent planes
//!    ([`oriented_normals`]) put outside, between two facing sheets, are
//!    removed, which opens the gaps the shell bridged (legs, fingers), then
//!    keep the largest face-connected solid (stray outliers are dropped).
//!    When removing the gap walls carving leaves ([`Carving::walls`]) too
//!    changes the genus, that cage is returned as well
//!    ([`OccupancyCage::opened`]): it opens a slot bridged by the voxels of
//!    its walls, or a false handle through a dent, and only a fit tells
//!    which;
//! 4. [`make_manifold`]: fill voxels until the boundary is a closed 2-manifold;
//! 5. the boundary quads between solid and empty voxels, outward, with shared
//!    lattice corners ([`boundary_quads`]);
//! 6. Taubin λ|μ smoothing ([`taubin_smoothed`]) so the cage is not a
//!    staircase, then [`snapped_to_points`]: vertices move along their
//!    normals towards the nearest points (at most `2h` per round, six damped
//!    rounds with a smoothing step each, no face turned over). The voxel
//!    boundary lies up to a voxel outside the points, the snapped cage on
//!    them, and its Catmull-Clark limit surface slightly inside, like the
//!    ellipsoid's.
//!
//! The genus comes from `χ = V − E + F = 2c − 2g` of the closed result.

use super::carve::{CarveStats, Carving, carve};
use super::detect::interior_probes;
use super::frame::PrincipalFrame;
use super::gaps::narrow_gap;
use super::normals::{SignedDistance, oriented_normals};
use super::sampling::{point_tree, sampling_radius, snapped_to_points};
use super::surface::{SurfaceTopology, reversed, signed_volume, surface_topology};
use super::voxel_repair::{RepairStats, make_manifold};
use super::voxel_surface::{boundary_quads, taubin_smoothed};
use super::voxels::VoxelGrid;
use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::mesh::PolyMesh;

/// Empty voxels around the occupied box on each side: room for the sampling
/// balls (at most `2h`), the closing's dilations and one free layer for the
/// flood fill to pass around the object.
const MARGIN: usize = 3 + MAX_CLOSING;

/// Voxels a narrow gap must span to stay open ([`super::carve`]).
const GAP_VOXELS: Real = 1.5;

/// Largest closing tried when the plain fill leaks.
const MAX_CLOSING: usize = 3;

/// Fill accepted when at most this fraction of interior probes is outside;
/// a closing repairs a leak when it leaves at most this fraction outside,
/// and at most this fraction of those the plain fill left outside.
const LEAK_LIMIT: Real = 0.25;

/// The occupancy cage and how it was built.
#[derive(Clone, Debug)]
pub struct OccupancyCage {
    /// Closed, outward-oriented quad mesh.
    pub mesh: PolyMesh,
    /// The cage with the gap walls ([`Carving::walls`]) removed too, when its
    /// genus differs from [`OccupancyCage::mesh`]'s: a slot or hole that
    /// voxels bridged, or a dent opened into a false handle. The fit tries
    /// both ([`crate::fit::fit_from_start`]).
    pub opened: Option<Opened>,
    /// Components, Euler characteristic and genus of [`OccupancyCage::mesh`].
    pub topology: SurfaceTopology,
    /// Grid size in voxels, margins included.
    pub dims: [usize; 3],
    /// Voxel side `h`.
    pub voxel: Real,
    /// Narrow-gap width that set `h` ([`narrow_gap`]), if any was found.
    pub gap: Option<Real>,
    /// Sampling radius `r` used for the shell.
    pub radius: Real,
    /// Voxels of the shell.
    pub occupied: usize,
    /// Solid voxels of the final set.
    pub solid: usize,
    /// Closing radius `k` used (0: plain fill).
    pub closing: usize,
    /// Fraction of interior probes outside the chosen solid.
    pub leak: Real,
    /// What the signed-distance carving did.
    pub carved: CarveStats,
    /// Solid components dropped (outliers, clutter).
    pub dropped_components: usize,
    /// What the manifold repair filled.
    pub repair: RepairStats,
}

/// The occupancy cage without its gap walls ([`OccupancyCage::opened`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Opened {
    /// Closed, outward-oriented quad mesh.
    pub mesh: PolyMesh,
    /// Its genus.
    pub genus: i64,
    /// The centres of the wall voxels removed.
    pub walls: Vec<Point3>,
    /// The voxel side.
    pub voxel: Real,
}

/// A carved solid's cage.
struct Carved {
    mesh: PolyMesh,
    topology: SurfaceTopology,
    solid: usize,
    dropped_components: usize,
    repair: RepairStats,
}

/// The occupancy cage of `points` (module docs).
pub fn occupancy_cage(
    points: &[Point3],
    frame: &PrincipalFrame,
    resolution: usize,
    max_refinement: Real,
    smoothing_steps: usize,
) -> Result<OccupancyCage> {
    let ext = frame.extents();
    let coarse = ext[0].max(ext[1]).max(ext[2]) / resolution as Real;
    let tree = point_tree(points);
    let normals = oriented_normals(points, &tree);
    let spacing = sampling_radius(points, &tree);
    let gap = narrow_gap(
        points,
        &normals,
        &tree,
        coarse / 16.0,
        spacing,
        1.5 * coarse,
    );
    let h = gap.map_or(coarse, |g| {
        (g / GAP_VOXELS).clamp(coarse / max_refinement.max(1.0), coarse)
    });
    let cells = ext.map(|e| (e / h).floor() as usize + 1);
    // Centre the occupied box in its cells.
    let lo: [Real; 3] = [0, 1, 2].map(|k| frame.lo[k] - 0.5 * (cells[k] as Real * h - ext[k]));
    let dims = cells.map(|c| c + 2 * MARGIN);
    let r = spacing.clamp(0.01 * h, 2.0 * h);
    let mut grid = VoxelGrid::new(dims);
    let voxel_of = |x: Real, k: usize| ((x - lo[k]) / h).floor() as isize + MARGIN as isize;
    for p in points {
        let l = frame.local(p);
        let (a, b) = (
            [0, 1, 2].map(|k| voxel_of(l[k] - r, k)),
            [0, 1, 2].map(|k| voxel_of(l[k] + r, k)),
        );
        for z in a[2]..=b[2] {
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    let v = [x, y, z];
                    // Squared distance from the point to the voxel's box.
                    let d2: Real = (0..3)
                        .map(|k| {
                            let lo_k = lo[k] + (v[k] - MARGIN as isize) as Real * h;
                            let gap = (lo_k - l[k]).max(l[k] - lo_k - h).max(0.0);
                            gap * gap
                        })
                        .sum();
                    if d2 <= r * r
                        && let Some(n) = grid.index(v)
                    {
                        grid.solid[n] = true;
                    }
                }
            }
        }
    }
    let occupied = grid.count();
    let probes: Vec<usize> = interior_probes(points, frame)
        .iter()
        .filter_map(|p| {
            let l = frame.local(p);
            grid.index([0, 1, 2].map(|k| voxel_of(l[k], k)))
        })
        .collect();
    let leak_of = |g: &VoxelGrid| {
        let out = probes.iter().filter(|&&n| !g.solid[n]).count();
        out as Real / probes.len().max(1) as Real
    };
    let mut closing = 0;
    let mut solid = grid.closed_solid(0);
    let mut leak = leak_of(&solid);
    let repaired = LEAK_LIMIT.min(LEAK_LIMIT * leak);
    if leak > LEAK_LIMIT
        && let Some((k, closed, l)) = (1..=MAX_CLOSING)
            .map(|k| {
                let closed = grid.closed_solid(k);
                let l = leak_of(&closed);
                (k, closed, l)
            })
            .find(|&(_, _, l)| l <= repaired)
    {
        (closing, solid, leak) = (k, closed, l);
    }
    let sd = SignedDistance::new(points, &normals, &tree);
    let local = |x: [Real; 3]| {
        let l = Vector3::from_fn(|k, _| lo[k] + (x[k] - MARGIN as Real) * h);
        frame.world(&l)
    };
    // The shell grid has the solid's dimensions.
    let voxel_index = |p: &Point3| {
        let l = frame.local(p);
        grid.index([0, 1, 2].map(|k| voxel_of(l[k], k)))
    };
    let Carving {
        stats: carved,
        walls,
    } = carve(&mut solid, &sd, h, local, voxel_index);
    let cage_of = |mut solid: VoxelGrid| -> Result<Carved> {
        let mut dropped_components = solid.keep_largest_component();
        let repair = make_manifold(&mut solid);
        dropped_components += solid.keep_largest_component();
        if solid.count() == 0 {
            return Err(Error::input(
                "the points' occupancy is empty; cannot build an occupancy cage",
            ));
        }
        let blocky = boundary_quads(&solid, |c| local(c.map(|x| x as Real)))?;
        let smooth = taubin_smoothed(&blocky, smoothing_steps);
        let mut mesh = snapped_to_points(&smooth, points, &tree, 2.0 * h)?;
        if signed_volume(&mesh) < 0.0 {
            mesh = reversed(&mesh)?;
        }
        let topology = surface_topology(&mesh)?;
        if topology.boundary_loops != 0 {
            return Err(Error::Topology(format!(
                "occupancy cage has {} boundary loops; expected a closed surface",
                topology.boundary_loops
            )));
        }
        Ok(Carved {
            mesh,
            topology,
            solid: solid.count(),
            dropped_components,
            repair,
        })
    };
    // A cage without the walls that cannot be built is not offered.
    let opened = if walls.is_empty() {
        None
    } else {
        let mut without_walls = solid.clone();
        for &n in &walls {
            without_walls.solid[n] = false;
        }
        cage_of(without_walls).ok()
    };
    let wall_centres: Vec<Point3> = walls
        .iter()
        .map(|&n| local(solid.coords(n).map(|x| x as Real + 0.5)))
        .collect();
    let Carved {
        mesh,
        topology,
        solid,
        dropped_components,
        repair,
    } = cage_of(solid)?;
    let opened = opened
        .filter(|o| o.topology.genus != topology.genus)
        .map(|o| Opened {
            mesh: o.mesh,
            genus: o.topology.genus,
            walls: wall_centres,
            voxel: h,
        });
    Ok(OccupancyCage {
        mesh,
        opened,
        topology,
        dims,
        voxel: h,
        gap,
        radius: r,
        occupied,
        solid,
        closing,
        leak,
        carved,
        dropped_components,
        repair,
    })
}
