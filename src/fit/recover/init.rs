//! Initial models for recovering a shape from a volume: a small sphere-like
//! cage at a seed point (grown by the inflation force), or the smoothed
//! boundary of the thresholded object, one closed cage per part (any genus).

use crate::error::{Error, Result};
use crate::fit::init::signed_volume;
use crate::math::{Point3, Real};
use crate::mesh::PolyMesh;
use crate::subdivision::{RefineOptions, Refiner};
use crate::volume::Volume;

use super::part_cage::part_cage;
use super::voxel_components::{components, iso_crossings};

/// A closed 26-vertex quad cage (the cube refined once, projected on a
/// sphere) whose Catmull-Clark limit surface is a near-sphere of radius
/// about `radius` around `centre`.
pub fn seed_cage(centre: Point3, radius: Real) -> Result<PolyMesh> {
    if !(radius.is_finite() && radius > 0.0) {
        return Err(Error::input(format!(
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
                return Err(Error::input(format!(
                    "seed ({}, {}, {}) lies outside the volume",
                    s.x, s.y, s.z
                )));
            }
            let l = label[volume.index(c[0] as usize, c[1] as usize, c[2] as usize)];
            if l == u32::MAX {
                return Err(Error::input(format!(
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
            Error::input(format!(
                "no voxel is {} the level {level}: nothing to recover",
                if bright_inside { "above" } else { "below" }
            ))
        })?,
    };
    if sizes[chosen] < 8 {
        return Err(Error::input(format!(
            "the object's component has only {} voxels; too small to recover",
            sizes[chosen]
        )));
    }
    let (lo, hi) = boxes[chosen];
    let extent = (0..3).map(|a| hi[a] - lo[a] + 1).max().unwrap_or(1);
    let block = extent.div_ceil(resolution.max(2)).max(1);
    let main =
        part_cage(volume, &label, chosen as u32, boxes[chosen], block)?.ok_or_else(|| {
            Error::input(format!(
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
            // (A part voxel is in its own neighbourhood: checked first.)
            let apart = |i: usize| {
                let c = volume.voxel(i);
                !in_part(i)
                    && !NEIGHBOURHOOD
                        .iter()
                        .filter_map(|&d| volume.offset_index(c, d))
                        .any(in_part)
            };
            let lost = |i: usize| {
                force_label[i] != u32::MAX && overlap[force_label[i] as usize] > 0 && apart(i)
            };
            boundary.extend(iso_crossings(forces, &force_label, lost, level));
        }
    }
    Ok(ComponentCage {
        mesh: PolyMesh::disjoint_union(&meshes),
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

/// The block and its 26 neighbours.
pub(super) const NEIGHBOURHOOD: [[isize; 3]; 27] = {
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

/// The mesh with faces reversed if its signed volume is negative (a
/// voxel-to-world map with negative determinant mirrors orientation).
pub(super) fn oriented_outward(mesh: PolyMesh) -> Result<PolyMesh> {
    if signed_volume(&mesh) < 0.0 {
        crate::fit::init::surface::reversed(&mesh)
    } else {
        Ok(mesh)
    }
}
