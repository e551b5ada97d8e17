//! One part's cage for [`super::component_cage`]: its voxels coarsened to
//! blocks, or, when the blocks lose a thin part, the voxels' own boundary
//! simplified.

use crate::error::Result;
use crate::fit::init::surface_topology;
use crate::fit::init::voxel_repair::make_manifold;
use crate::fit::init::voxel_surface::{boundary_quads, taubin_smoothed};
use crate::fit::init::voxels::VoxelGrid;
use crate::math::Real;
use crate::mesh::{PolyMesh, simplified};
use crate::volume::Volume;

use super::init::{NEIGHBOURHOOD, oriented_outward};

/// One part's cage ([`component_cage`]'s construction for component
/// `id` of `label`, in its box `lo..=hi`, at `block`-voxel blocks).
pub(super) struct PartCage {
    pub mesh: PolyMesh,
    pub lost: usize,
    pub simplified_from: Option<usize>,
    pub genus: i64,
}

/// The cage of component `id` (see [`component_cage`]); `None` when it
/// vanishes at every block size tried.
pub(super) fn part_cage(
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

/// A component whose blocks lose more than this share of its voxels gets
/// the simplified cage.
const LOST_PART: Real = 0.002;

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
