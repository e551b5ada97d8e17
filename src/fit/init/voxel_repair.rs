//! Makes the boundary of a voxel set a closed 2-manifold by filling voxels.
//!
//! The boundary surface of a voxel set (the quads between solid and empty
//! voxels, voxels outside the grid counting as empty) is locally determined
//! at each lattice vertex by the eight voxels around it, a 2×2×2 block. The
//! quads of the surface at the vertex are the block's 12 internal faces whose
//! two voxels differ; each such quad joins two of the six lattice half-edges
//! leaving the vertex. The surface is a 2-manifold at the vertex exactly when
//! this *link graph* is empty or a single cycle: every half-edge has degree 0
//! or 2 (degree 4 is the edge-only contact `■□ / □■` around an edge) and the
//! arcs form one loop (two loops are, e.g., two solid voxels sharing only the
//! vertex, or two empty voxels doing the same inside a solid).
//!
//! **Rule.** Repeat until a pass changes nothing: (1) fill cavities (empty
//! voxels not 6-connected to the grid border), so every empty voxel is
//! outside; (2) at every non-manifold lattice vertex, fill the empty in-grid
//! voxel of its block with the most solid face neighbours (the smallest
//! `(x, y, z)` on ties). Filling only grows the solid, the outward-facing side, so
//! the cage stays around the points.
//!
//! **Termination.** Each pass that does not stop fills at least one voxel, so
//! the number of solid voxels strictly increases and is bounded by the number
//! of in-grid voxels `N`: at most `N + 1` passes run. A fill is always
//! possible at a non-manifold vertex: if every empty voxel of its block were
//! outside the grid, the in-grid voxels of the block (a 2×2×2, 2×2×1, 2×1×1
//! or 1×1×1 box) would all be solid, and a box against empty space has a
//! single-cycle link. When the loop stops no vertex is non-manifold and no
//! cavity exists, so the boundary is a closed, consistently oriented
//! 2-manifold (a fully solid grid, the worst case, gives its box).

use super::voxels::VoxelGrid;

/// Per 8-bit block configuration (bit `x + 2y + 4z` set when voxel
/// `(x, y, z)` of the block is solid): true when the boundary surface is a
/// 2-manifold at the block's centre vertex.
pub fn manifold_table() -> [bool; 256] {
    let mut table = [true; 256];
    for (config, entry) in table.iter_mut().enumerate() {
        *entry = link_is_one_cycle(config as u8);
    }
    table
}

/// The link-graph test of the module docs for one configuration.
fn link_is_one_cycle(config: u8) -> bool {
    // Nodes: half-edge along axis `a` in direction + (2a) or − (2a + 1).
    let mut arcs: Vec<(usize, usize)> = Vec::new();
    for b in 0..8usize {
        for a in 0..3 {
            if b & (1 << a) != 0 {
                continue;
            }
            let c = b | (1 << a);
            let (sb, sc) = (config >> b & 1, config >> c & 1);
            if sb == sc {
                continue;
            }
            let (a1, a2) = ((a + 1) % 3, (a + 2) % 3);
            let node = |axis: usize| 2 * axis + if b & (1 << axis) != 0 { 0 } else { 1 };
            arcs.push((node(a1), node(a2)));
        }
    }
    if arcs.is_empty() {
        return true;
    }
    let mut degree = [0usize; 6];
    for &(p, q) in &arcs {
        degree[p] += 1;
        degree[q] += 1;
    }
    if degree.iter().any(|&d| d != 0 && d != 2) {
        return false;
    }
    // All degrees 0 or 2: the arcs form disjoint cycles; count components.
    let mut parent = [0usize, 1, 2, 3, 4, 5];
    fn find(parent: &mut [usize; 6], mut x: usize) -> usize {
        while parent[x] != x {
            x = parent[x];
        }
        x
    }
    for &(p, q) in &arcs {
        let (rp, rq) = (find(&mut parent, p), find(&mut parent, q));
        parent[rp] = rq;
    }
    let roots = (0..6)
        .filter(|&n| degree[n] > 0 && find(&mut parent, n) == n)
        .count();
    roots == 1
}

/// Voxels filled by [`make_manifold`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RepairStats {
    /// Cavity voxels filled.
    pub cavities: usize,
    /// Voxels filled at non-manifold vertices.
    pub repairs: usize,
    /// Passes run.
    pub passes: usize,
}

/// Applies the rule of the module docs until the boundary is a closed 2-manifold.
pub fn make_manifold(grid: &mut VoxelGrid) -> RepairStats {
    let table = manifold_table();
    let mut stats = RepairStats::default();
    let [d0, d1, d2] = grid.dims.map(|d| d as isize);
    loop {
        stats.passes += 1;
        let cavities = grid.fill_cavities();
        stats.cavities += cavities;
        let mut repairs = 0;
        for z in 0..=d2 {
            for y in 0..=d1 {
                for x in 0..=d0 {
                    let block = |b: usize| {
                        [
                            x - 1 + (b & 1) as isize,
                            y - 1 + (b >> 1 & 1) as isize,
                            z - 1 + (b >> 2 & 1) as isize,
                        ]
                    };
                    let config =
                        (0..8).fold(0u8, |acc, b| acc | (u8::from(grid.get(block(b))) << b));
                    if table[config as usize] {
                        continue;
                    }
                    let pick = (0..8)
                        .map(block)
                        .filter(|&v| grid.index(v).is_some() && !grid.get(v))
                        .max_by_key(|&v| (solid_face_neighbours(grid, v), std::cmp::Reverse(v)));
                    if let Some(v) = pick
                        && let Some(n) = grid.index(v)
                    {
                        grid.solid[n] = true;
                        repairs += 1;
                    }
                }
            }
        }
        stats.repairs += repairs;
        if cavities == 0 && repairs == 0 {
            return stats;
        }
    }
}

/// Number of solid face neighbours of voxel `v`.
fn solid_face_neighbours(grid: &VoxelGrid, v: [isize; 3]) -> usize {
    super::voxels::FACE_NEIGHBOURS
        .iter()
        .filter(|d| grid.get([v[0] + d[0], v[1] + d[1], v[2] + d[2]]))
        .count()
}
