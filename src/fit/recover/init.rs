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
    /// The closed, outward quad cage: one closed surface per part kept.
    pub mesh: PolyMesh,
    /// Voxels of the parts kept.
    pub voxels: usize,
    /// Components of the thresholded volume.
    pub components: usize,
    /// Components kept (the object's parts; 1 with a seed).
    pub parts: usize,
    /// Voxels per block of the coarse cage along each axis.
    pub block: usize,
    /// Voxels of the parts more than a block from their coarse cages'
    /// blocks (parts they lost).
    pub lost_voxels: usize,
    /// The block size (1: the voxels) whose boundary was simplified into
    /// the largest part's cage, when its coarse blocks lost a part; `None`:
    /// the coarse blocks' boundary is the cage.
    pub simplified_from: Option<usize>,
    /// Genus of the cage: the sum over its parts.
    pub genus: i64,
    /// Points on the object's iso-surface: on every voxel edge from a voxel
    /// of a part to one outside the object, where the linear interpolant
    /// crosses the level (the vertices marching cubes would place; world
    /// coordinates, in voxel order); then the same in the volume the forces
    /// see, where it holds the object but the parts do not (a leg the
    /// cage's smoothing cut off). The recovery's two-sided forces pull the
    /// surface towards those it leaves far, so such a leg grows back.
    pub boundary: Vec<Point3>,
}

/// Components of at least this share of the largest one's voxels are parts
/// of the object (without a seed): a leg, a hoof, a slat that the
/// threshold cut off the body. Marching cubes keeps every component; this
/// keeps the ones a cage can carry and leaves out noise specks.
pub const PART_SHARE: Real = 0.01;

/// A component of the forces' volume gives the iso-surface points only
/// while it has at most this many times the voxels of the parts it
/// overlaps (parts the cage's smoothing cut off: thin legs, slats); a
/// larger one has leaked into the surroundings (a dark ventricle into the
/// sulci), and the parts' own iso-surface is taken instead.
const FORCE_GROWTH: Real = 1.5;

/// Components smaller than this many voxels are never parts: a cage
/// cannot follow anything thinner than about two voxels each way.
pub const MIN_PART_VOXELS: usize = 27;

/// The cage of the object in `volume`, thresholded at `level` (`{v > level}`,
/// `< level` for dark objects) and split into 6-connected components: the
/// component containing `seed` if given, else the largest and every other
/// component of at least [`PART_SHARE`] of its voxels (and
/// [`MIN_PART_VOXELS`]), each with a closed cage of its own.
///
/// A component is coarsened to blocks of `b³` voxels (`b` chosen so the
/// largest part's longest side spans about `resolution` blocks, the same
/// `b` for every part; a block is solid when at least half its voxels
/// are), cavities are filled, the block set is made a 2-manifold, and its
/// boundary quads, Taubin-smoothed, form the cage. When the blocks lose a
/// part of it (more than 0.2 % of the component's voxels lie more than a
/// block from every solid block: a leg, a rod, a sheet thinner than the
/// blocks), the same boundary of the voxels themselves is simplified
/// ([`simplified`]) towards as many vertices instead (at most a tenth of
/// its own, else blocks 2, 4, … voxels wide are tried): a triangle cage,
/// fine where the object is thin, that keeps every part and hole down to a
/// voxel or two thick. Holes narrower than about two blocks in an object
/// that lost no part close up. A small part that vanishes at every block
/// size is left out. `forces` is the volume the recovery's forces see (the
/// same grid, smoothed less than `volume`, or `volume` itself): where its
/// components that overlap a part hold voxels the parts do not, their
/// iso-surface points join the parts' ([`ComponentCage::boundary`]).
pub fn component_cage(
    volume: &Volume,
    forces: &Volume,
    level: Real,
    bright_inside: bool,
    seed: Option<Point3>,
    resolution: usize,
) -> Result<ComponentCage> {
    let (label, sizes, boxes) = components(volume, level, bright_inside);
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
    let (lo, hi) = boxes[chosen];
    let extent = (0..3).map(|a| hi[a] - lo[a] + 1).max().unwrap_or(1);
    let block = extent.div_ceil(resolution.max(2)).max(1);
    let main =
        part_cage(volume, &label, chosen as u32, boxes[chosen], block)?.ok_or_else(|| {
            Error::Input(format!(
                "the object ({} voxels) vanishes at {block}-voxel blocks; raise the resolution",
                sizes[chosen]
            ))
        })?;
    let mut others: Vec<usize> = if seed.is_some() {
        Vec::new()
    } else {
        let least = MIN_PART_VOXELS.max((PART_SHARE * sizes[chosen] as Real).ceil() as usize);
        (0..sizes.len())
            .filter(|&i| i != chosen && sizes[i] >= least)
            .collect()
    };
    // The largest first, then the others by size (ties by label): the
    // cage's vertex order does not depend on how the voxels were scanned.
    others.sort_by(|&a, &b| sizes[b].cmp(&sizes[a]).then(a.cmp(&b)));
    let mut kept = vec![chosen];
    let mut meshes = vec![main.mesh];
    let (mut lost, mut genus) = (main.lost, main.genus);
    for &i in &others {
        if let Some(part) = part_cage(volume, &label, i as u32, boxes[i], block)? {
            kept.push(i);
            meshes.push(part.mesh);
            lost += part.lost;
            genus += part.genus;
        }
    }
    let mut part = vec![false; sizes.len()];
    for &i in &kept {
        part[i] = true;
    }
    let in_part = |i: usize| label[i] != u32::MAX && part[label[i] as usize];
    let mut boundary = iso_crossings(volume, &label, in_part, level);
    if !std::ptr::eq(volume, forces) {
        // Where the forces' volume holds the object but the parts do not
        // (a leg the cage's smoothing cut off), its own crossings, from
        // the forces' components that share a voxel with a part, unless
        // one of them has leaked.
        let (force_label, force_sizes, _) = components(forces, level, bright_inside);
        let mut overlap = vec![0usize; force_sizes.len()];
        for (i, &f) in force_label.iter().enumerate() {
            if f != u32::MAX && in_part(i) {
                overlap[f as usize] += 1;
            }
        }
        let leaked = overlap
            .iter()
            .zip(&force_sizes)
            .any(|(&o, &n)| o > 0 && n as Real > FORCE_GROWTH * o as Real);
        if !leaked {
            // Voxels a voxel or more from every part voxel: not the rim
            // that the extra smoothing shaves off every part (taking that
            // would only add points along every fold of a brain).
            let dims = volume.dims();
            let apart = |i: usize| {
                let c = [
                    i % dims[0],
                    (i / dims[0]) % dims[1],
                    i / (dims[0] * dims[1]),
                ];
                !NEIGHBOURHOOD.iter().any(|d| {
                    let w = [0, 1, 2].map(|a| c[a] as isize + d[a]);
                    (0..3).all(|a| w[a] >= 0 && w[a] < dims[a] as isize)
                        && in_part(volume.index(w[0] as usize, w[1] as usize, w[2] as usize))
                })
            };
            let lost = |i: usize| {
                force_label[i] != u32::MAX && overlap[force_label[i] as usize] > 0 && apart(i)
            };
            boundary.extend(iso_crossings(forces, &force_label, lost, level));
        }
    }
    Ok(ComponentCage {
        mesh: disjoint_union(&meshes),
        voxels: kept.iter().map(|&i| sizes[i]).sum(),
        components: sizes.len(),
        parts: kept.len(),
        block,
        lost_voxels: lost,
        simplified_from: main.simplified_from,
        genus,
        boundary,
    })
}

/// The 6-connected components of the voxels inside the object: every
/// voxel's label (`u32::MAX` outside), each component's voxel count and
/// its box of voxel indices.
#[allow(clippy::type_complexity)]
fn components(
    volume: &Volume,
    level: Real,
    bright_inside: bool,
) -> (Vec<u32>, Vec<usize>, Vec<([usize; 3], [usize; 3])>) {
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
    (label, sizes, boxes)
}

/// One part's cage ([`component_cage`]'s construction for component
/// `id` of `label`, in its box `lo..=hi`, at `block`-voxel blocks).
struct PartCage {
    mesh: PolyMesh,
    lost: usize,
    simplified_from: Option<usize>,
    genus: i64,
}

/// The cage of component `id` (see [`component_cage`]); `None` when it
/// vanishes at every block size tried.
fn part_cage(
    volume: &Volume,
    label: &[u32],
    id: u32,
    (lo, hi): ([usize; 3], [usize; 3]),
    block: usize,
) -> Result<Option<PartCage>> {
    let grid_of = |block: usize| -> Result<Option<(VoxelGrid, PolyMesh)>> {
        let mut grid = block_grid(volume, label, id, (lo, hi), block);
        grid.fill_cavities();
        grid.keep_largest_component();
        make_manifold(&mut grid);
        grid.keep_largest_component();
        if grid.count() == 0 {
            return Ok(None);
        }
        // Block corner c is at voxel index lo + (c − margin) b − ½ (voxel faces).
        let corner = |c: [usize; 3]| {
            volume.world(
                [0, 1, 2]
                    .map(|a| lo[a] as Real + (c[a] as Real - MARGIN as Real) * block as Real - 0.5),
            )
        };
        let mesh = taubin_smoothed(&boundary_quads(&grid, corner)?, 10);
        Ok(Some((grid, mesh)))
    };
    let coarse = grid_of(block)?;
    // Voxels of the component more than a block from every solid block: a
    // part the blocks lost (a leg, a rod, a thin sheet).
    let (mut size, mut lost) = (0usize, 0usize);
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                if label[volume.index(x, y, z)] != id {
                    continue;
                }
                size += 1;
                let g = [x - lo[0], y - lo[1], z - lo[2]].map(|c| (c / block + MARGIN) as isize);
                let near = coarse.as_ref().is_some_and(|(grid, _)| {
                    NEIGHBOURHOOD
                        .iter()
                        .any(|d| grid.get([g[0] + d[0], g[1] + d[1], g[2] + d[2]]))
                });
                lost += usize::from(!near);
            }
        }
    }
    // When the blocks lost a part, the voxels' own boundary is simplified
    // towards the coarse cage's number of vertices (at least a cube's
    // refined once when the blocks kept nothing), with edges up to two
    // blocks long (along the coarsest axis, so anisotropic voxels do not
    // hold it back) so the cells stay about as even as the blocks'. Its
    // topology may keep it above that; it is taken when it reaches that
    // number or has at most a tenth of the boundary's vertices, else the
    // boundary of blocks 2, 4, … voxels wide is tried (fine structure such
    // as a folded sheet's tunnels fades at coarser blocks).
    let target = coarse
        .as_ref()
        .map_or(MIN_PART_CAGE, |c| c.1.num_vertices());
    let max_edge = 2.0 * block as Real * volume.spacing().into_iter().fold(0.0, Real::max);
    let mut simplified_from = None;
    let mut mesh = coarse.map(|c| c.1);
    if lost as Real > LOST_PART * size as Real {
        let mut fine = 1;
        while fine < block.max(2) {
            let Some((_, boundary)) = grid_of(fine)? else {
                break;
            };
            let cage = simplified(&boundary, target, max_edge)?;
            if cage.num_vertices() <= target.max(boundary.num_vertices() / 10) {
                mesh = Some(cage);
                simplified_from = Some(fine);
                break;
            }
            fine *= 2;
        }
    }
    let Some(mesh) = mesh else {
        return Ok(None);
    };
    let mesh = oriented_outward(mesh)?;
    let genus = surface_topology(&mesh)?.genus;
    Ok(Some(PartCage {
        mesh,
        lost,
        simplified_from,
        genus,
    }))
}

/// The vertices a part whose blocks kept nothing is simplified towards:
/// a cube refined once.
const MIN_PART_CAGE: usize = 26;

/// The meshes side by side in one (vertices renumbered in order).
fn disjoint_union(meshes: &[PolyMesh]) -> PolyMesh {
    let mut out = PolyMesh {
        positions: Vec::new(),
        face_offsets: vec![0],
        face_vertices: Vec::new(),
    };
    for m in meshes {
        let base = out.positions.len() as u32;
        let at = out.face_vertices.len() as u32;
        out.positions.extend_from_slice(&m.positions);
        out.face_vertices
            .extend(m.face_vertices.iter().map(|&v| v + base));
        out.face_offsets
            .extend(m.face_offsets[1..].iter().map(|&o| o + at));
    }
    out
}

/// The points where the linear interpolant of `volume` crosses `level` on
/// the edges from a voxel `i` with `take(i)` to a face neighbour with
/// another `label`, which is not inside (components are maximal), in voxel
/// order.
fn iso_crossings(
    volume: &Volume,
    label: &[u32],
    take: impl Fn(usize) -> bool,
    level: Real,
) -> Vec<Point3> {
    let dims = volume.dims();
    let data = volume.data();
    let mut out = Vec::new();
    for i in (0..label.len()).filter(|&i| take(i)) {
        let chosen = label[i];
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
