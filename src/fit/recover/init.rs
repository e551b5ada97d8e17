//! Initial models for recovering a shape from a volume: a small sphere-like
//! cage at a seed point (grown by the inflation force), or the smoothed
//! boundary of a thresholded connected component (any genus).

use std::collections::VecDeque;

use crate::error::{Error, Result};
use crate::fit::init::voxel_repair::make_manifold;
use crate::fit::init::voxel_surface::{boundary_quads, taubin_smoothed};
use crate::fit::init::voxels::{FACE_NEIGHBOURS, VoxelGrid};
use crate::fit::init::{signed_volume, surface_topology};
use crate::math::{Point3, Real};
use crate::mesh::{PolyMesh, simplified};
use crate::subdivision::{RefineOptions, Refiner};
use crate::volume::Volume;

/// A closed 26-vertex quad cage (the cube refined once, projected on a
/// sphere) whose Catmull-Clark limit surface is a near-sphere of radius
/// about `radius` around `centre`.
pub fn seed_cage(centre: Point3, radius: Real) -> Result<PolyMesh> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(Error::Input(format!(
            "seed radius {radius} must be positive"
        )));
    }
    let cube = crate::examples::cube();
    let h = Refiner::new(&cube, &RefineOptions::default())?.refine_uniform(1)?;
    let p1 = h.stencil(0).apply(&cube.positions)?;
    let mut mesh = h.mesh(1, p1);
    // The limit surface of a cage on a sphere sits about 15 % inside it.
    let r = radius / 0.85;
    for p in &mut mesh.positions {
        let d = p.coords - Point3::new(0.5, 0.5, 0.5).coords;
        *p = centre + d.normalize() * r;
    }
    oriented_outward(mesh)
}

/// What [`component_cage`] built.
#[derive(Clone, Debug)]
pub struct ComponentCage {
    /// The closed, outward quad cage.
    pub mesh: PolyMesh,
    /// Voxels of the chosen component.
    pub voxels: usize,
    /// Components of the thresholded volume.
    pub components: usize,
    /// Voxels per block of the coarse cage along each axis.
    pub block: usize,
    /// Voxels of the component more than a block from the coarse cage's
    /// blocks (parts they lost).
    pub lost_voxels: usize,
    /// The block size (1: the voxels) whose boundary was simplified into
    /// the cage, when the coarse blocks lost a part; `None`: the coarse
    /// blocks' boundary is the cage.
    pub simplified_from: Option<usize>,
    /// Genus of the cage.
    pub genus: i64,
    /// Points on the component's iso-surface: on every voxel edge from a
    /// voxel of the component to one outside the object, where the linear
    /// interpolant crosses the level (the vertices marching cubes would
    /// place; world coordinates, in voxel order). The recovery's two-sided
    /// forces pull the surface towards those it leaves far.
    pub boundary: Vec<Point3>,
}

/// The cage of one connected component of `{v : v > level}` (`< level` for
/// dark objects) of `volume`: the component containing `seed` if given,
/// else the largest. The component is coarsened to blocks of `b³` voxels
/// (`b` chosen so the longest side spans about `resolution` blocks; a block
/// is solid when at least half its voxels are), cavities are filled, the
/// block set is made a 2-manifold, and its boundary quads, Taubin-smoothed,
/// form the cage. When the blocks lose a part (more than 0.2 % of the
/// component's voxels lie more than a block from every solid block: a leg,
/// a rod, a sheet thinner than the blocks), the same boundary of the voxels
/// themselves is simplified ([`simplified`]) towards as many vertices
/// instead (at most a tenth of its own, else blocks 2, 4, … voxels wide are
/// tried): a triangle cage, fine where the object is thin, that keeps every part and
/// hole down to a voxel or two thick. Holes narrower than about two blocks
/// in an object that lost no part close up.
pub fn component_cage(
    volume: &Volume,
    level: Real,
    bright_inside: bool,
    seed: Option<Point3>,
    resolution: usize,
) -> Result<ComponentCage> {
    let dims = volume.dims();
    let inside = |v: f32| {
        let v = v as Real;
        if bright_inside { v > level } else { v < level }
    };
    let n = volume.data().len();
    let mut label = vec![u32::MAX; n];
    let mut sizes: Vec<usize> = Vec::new();
    let mut boxes: Vec<([usize; 3], [usize; 3])> = Vec::new();
    let mut queue = VecDeque::new();
    let coords = |i: usize| {
        [
            i % dims[0],
            (i / dims[0]) % dims[1],
            i / (dims[0] * dims[1]),
        ]
    };
    for start in 0..n {
        if label[start] != u32::MAX || !inside(volume.data()[start]) {
            continue;
        }
        let id = sizes.len() as u32;
        label[start] = id;
        queue.push_back(start);
        let (mut size, mut lo, mut hi) = (0, coords(start), coords(start));
        while let Some(i) = queue.pop_front() {
            size += 1;
            let c = coords(i);
            for a in 0..3 {
                lo[a] = lo[a].min(c[a]);
                hi[a] = hi[a].max(c[a]);
            }
            for d in FACE_NEIGHBOURS {
                let w = [0, 1, 2].map(|a| c[a] as isize + d[a]);
                if (0..3).any(|a| w[a] < 0 || w[a] >= dims[a] as isize) {
                    continue;
                }
                let j = volume.index(w[0] as usize, w[1] as usize, w[2] as usize);
                if label[j] == u32::MAX && inside(volume.data()[j]) {
                    label[j] = id;
                    queue.push_back(j);
                }
            }
        }
        sizes.push(size);
        boxes.push((lo, hi));
    }
    let chosen = match seed {
        Some(s) => {
            let c = volume.continuous_index(&s).map(|x| x.round());
            if !volume.contains(&s) {
                return Err(Error::Input(format!(
                    "seed ({}, {}, {}) lies outside the volume",
                    s.x, s.y, s.z
                )));
            }
            let l = label[volume.index(c[0] as usize, c[1] as usize, c[2] as usize)];
            if l == u32::MAX {
                return Err(Error::Input(format!(
                    "seed ({}, {}, {}) is not inside the object: its voxel is {} the level {level}",
                    s.x,
                    s.y,
                    s.z,
                    if bright_inside {
                        "at or below"
                    } else {
                        "at or above"
                    }
                )));
            }
            l as usize
        }
        None => (0..sizes.len()).max_by_key(|&i| sizes[i]).ok_or_else(|| {
            Error::Input(format!(
                "no voxel is {} the level {level}: nothing to recover",
                if bright_inside { "above" } else { "below" }
            ))
        })?,
    };
    if sizes[chosen] < 8 {
        return Err(Error::Input(format!(
            "the object's component has only {} voxels; too small to recover",
            sizes[chosen]
        )));
    }
    let boundary = iso_crossings(volume, &label, chosen as u32, level);
    let (lo, hi) = boxes[chosen];
    let extent = (0..3).map(|a| hi[a] - lo[a] + 1).max().unwrap_or(1);
    let block = extent.div_ceil(resolution.max(2)).max(1);
    let grid_of = |block: usize| -> Result<(VoxelGrid, PolyMesh)> {
        let mut grid = block_grid(volume, &label, chosen as u32, (lo, hi), block);
        grid.fill_cavities();
        grid.keep_largest_component();
        make_manifold(&mut grid);
        grid.keep_largest_component();
        if grid.count() == 0 {
            return Err(Error::Input(format!(
                "the object ({} voxels) vanishes at {block}-voxel blocks; raise the resolution",
                sizes[chosen]
            )));
        }
        // Block corner c is at voxel index lo + (c − margin) b − ½ (voxel faces).
        let corner = |c: [usize; 3]| {
            volume.world(
                [0, 1, 2]
                    .map(|a| lo[a] as Real + (c[a] as Real - MARGIN as Real) * block as Real - 0.5),
            )
        };
        let mesh = taubin_smoothed(&boundary_quads(&grid, corner)?, 10);
        Ok((grid, mesh))
    };
    let (coarse, coarse_mesh) = grid_of(block)?;
    // Voxels of the component more than a block from every solid block: a
    // part the blocks lost (a leg, a rod, a thin sheet).
    let mut lost = 0usize;
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                if label[volume.index(x, y, z)] != chosen as u32 {
                    continue;
                }
                let g = [x - lo[0], y - lo[1], z - lo[2]].map(|c| (c / block + MARGIN) as isize);
                let near = NEIGHBOURHOOD
                    .iter()
                    .any(|d| coarse.get([g[0] + d[0], g[1] + d[1], g[2] + d[2]]));
                lost += usize::from(!near);
            }
        }
    }
    // When the blocks lost a part, the voxels' own boundary is simplified
    // towards the coarse cage's number of vertices, with edges up to two
    // blocks long (along the coarsest axis, so anisotropic voxels do not
    // hold it back) so the cells stay about as even as the blocks'. Its
    // topology may keep it above that; it is taken when it reaches that
    // number or has at most a tenth of the boundary's vertices, else the
    // boundary of blocks 2, 4, … voxels wide is tried (fine structure such
    // as a folded sheet's tunnels fades at coarser blocks).
    let target = coarse_mesh.num_vertices();
    let max_edge = 2.0 * block as Real * volume.spacing().into_iter().fold(0.0, Real::max);
    let mut simplified_from = None;
    let mut mesh = coarse_mesh;
    if lost as Real > LOST_PART * sizes[chosen] as Real {
        let mut fine = 1;
        while fine < block {
            let boundary = grid_of(fine)?.1;
            let cage = simplified(&boundary, target, max_edge)?;
            if cage.num_vertices() <= target.max(boundary.num_vertices() / 10) {
                mesh = cage;
                simplified_from = Some(fine);
                break;
            }
            fine *= 2;
        }
    }
    let mesh = oriented_outward(mesh)?;
    let topo = surface_topology(&mesh)?;
    Ok(ComponentCage {
        mesh,
        voxels: sizes[chosen],
        components: sizes.len(),
        block,
        lost_voxels: lost,
        simplified_from,
        genus: topo.genus,
        boundary,
    })
}

/// The points where the linear interpolant of `volume` crosses `level` on
/// the edges from a voxel labelled `chosen` to a face neighbour with another
/// label that is not inside (any neighbour outside the component is outside
/// the object: components are maximal), in voxel order.
fn iso_crossings(volume: &Volume, label: &[u32], chosen: u32, level: Real) -> Vec<Point3> {
    let dims = volume.dims();
    let data = volume.data();
    let mut out = Vec::new();
    for i in (0..label.len()).filter(|&i| label[i] == chosen) {
        let c = [
            i % dims[0],
            (i / dims[0]) % dims[1],
            i / (dims[0] * dims[1]),
        ];
        let a = data[i] as Real;
        for d in FACE_NEIGHBOURS {
            let w = [0, 1, 2].map(|k| c[k] as isize + d[k]);
            if (0..3).any(|k| w[k] < 0 || w[k] >= dims[k] as isize) {
                continue;
            }
            let j = volume.index(w[0] as usize, w[1] as usize, w[2] as usize);
            if label[j] == chosen {
                continue;
            }
            let b = data[j] as Real;
            let t = if a == b {
                0.5
            } else {
                ((a - level) / (a - b)).clamp(0.0, 1.0)
            };
            out.push(volume.world([0, 1, 2].map(|k| c[k] as Real + t * d[k] as Real)));
        }
    }
    out
}

/// A component whose blocks lose more than this share of its voxels gets
/// the simplified cage.
const LOST_PART: Real = 0.002;

/// The block and its 26 neighbours.
const NEIGHBOURHOOD: [[isize; 3]; 27] = {
    let mut n = [[0isize; 3]; 27];
    let mut i = 0;
    while i < 27 {
        n[i] = [
            (i % 3) as isize - 1,
            ((i / 3) % 3) as isize - 1,
            (i / 9) as isize - 1,
        ];
        i += 1;
    }
    n
};

/// Empty cells around the blocks of [`block_grid`].
const MARGIN: usize = 2;

/// The blocks of `block³` voxels of the box `lo..=hi` holding component
/// `chosen` of `label`, with [`MARGIN`] empty blocks around: a block is
/// solid when at least half its voxels are in the component.
fn block_grid(
    volume: &Volume,
    label: &[u32],
    chosen: u32,
    (lo, hi): ([usize; 3], [usize; 3]),
    block: usize,
) -> VoxelGrid {
    let gdims = [0, 1, 2].map(|a| (hi[a] - lo[a] + 1).div_ceil(block) + 2 * MARGIN);
    let mut grid = VoxelGrid::new(gdims);
    let mut count = vec![0u32; grid.solid.len()];
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                if label[volume.index(x, y, z)] == chosen {
                    let g =
                        [x - lo[0], y - lo[1], z - lo[2]].map(|c| (c / block + MARGIN) as isize);
                    if let Some(i) = grid.index(g) {
                        count[i] += 1;
                    }
                }
            }
        }
    }
    let half = (block * block * block).div_ceil(2) as u32;
    for (s, &c) in grid.solid.iter_mut().zip(&count) {
        *s = c >= half.max(1);
    }
    grid
}

/// The mesh with faces reversed if its signed volume is negative (a
/// voxel-to-world map with negative determinant mirrors orientation).
fn oriented_outward(mesh: PolyMesh) -> Result<PolyMesh> {
    if signed_volume(&mesh) < 0.0 {
        crate::fit::init::surface::reversed(&mesh)
    } else {
        Ok(mesh)
    }
}
