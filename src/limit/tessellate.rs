//! Dense limit-surface tessellation with shared edge and corner samples.

use std::collections::HashMap;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::mesh::PolyMesh;
use crate::subdivision::Refiner;

use super::PatchTable;

/// A point of the control mesh's topology that samples can share.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Key {
    /// A control vertex.
    Vertex(u32),
    /// The midpoint of a control edge.
    Mid(u32),
    /// The centre of a face.
    Centre(u32),
    /// Sample `j` (of `0..=k`, counted from the lesser end key) on a tessellation edge.
    OnEdge(Key2, u32),
}

/// A tessellation edge, named by its two end keys in increasing order.
type Key2 = (Corner, Corner);
/// Corner keys (a subset of [`Key`] that cannot nest).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Corner {
    Vertex(u32),
    Mid(u32),
    Centre(u32),
}

impl From<Corner> for Key {
    fn from(c: Corner) -> Key {
        match c {
            Corner::Vertex(v) => Key::Vertex(v),
            Corner::Mid(e) => Key::Mid(e),
            Corner::Centre(f) => Key::Centre(f),
        }
    }
}

/// One `k × k` grid: base face, parameter origin and axes, and its corner keys.
struct Tile {
    face: u32,
    origin: [Real; 2],
    size: Real,
    corners: [Corner; 4],
}

/// Tessellates the limit surface: each quad face becomes a `k × k` grid of
/// limit samples; when the mesh has any non-quad face, every face is split
/// into its quad sub-faces (corner, edge midpoint, centre, edge midpoint) and
/// each sub-face gets the `k × k` grid, so neighbouring faces always meet with
/// the same number of samples. Samples on shared edges and vertices are
/// shared, so a closed control mesh gives a watertight tessellation. Returns
/// the mesh and one unit normal per vertex (`Pu × Pv`).
pub fn tessellate(
    refiner: &Refiner,
    positions: &[Point3],
    k: usize,
) -> Result<(PolyMesh, Vec<Vector3>)> {
    let plan = Tessellation::new(refiner, k)?;
    let level = &refiner.level;
    if positions.len() != level.num_vertices {
        return Err(Error::size_mismatch(format!(
            "{} positions for a mesh of {} vertices",
            positions.len(),
            level.num_vertices
        )));
    }
    let table = PatchTable::new(refiner, positions, 1)?;
    let (pts, normals) = plan.evaluate(&table, None)?;
    Ok((plan.mesh(pts)?, normals))
}

/// The topology of a [`tessellate`]d surface: its tiles, its quads, and the
/// tile sample each vertex is evaluated at, so that the samples can be
/// evaluated again, all or those of some faces, when the control points
/// move.
pub struct Tessellation {
    tiles: Vec<Tile>,
    /// Per vertex: the tile and grid sample it is evaluated at.
    owner: Vec<(u32, u32)>,
    faces: Vec<Vec<u32>>,
    k: usize,
}

impl Tessellation {
    /// The tessellation of `refiner`'s mesh, `k × k` per quad (tile).
    pub fn new(refiner: &Refiner, k: usize) -> Result<Self> {
        if k == 0 || k > 1024 {
            return Err(Error::input(format!(
                "tessellation rate {k} must be between 1 and 1024"
            )));
        }
        let level = &refiner.level;
        let split = (0..level.num_faces()).any(|f| level.face_vertices(f).len() != 4);
        let mut tiles = Vec::new();
        // Hole faces are left out (they still shape their neighbours).
        for f in (0..level.num_faces()).filter(|&f| !refiner.holes.get(f).copied().unwrap_or(false))
        {
            let fv = level.face_vertices(f);
            let fe = level.face_edge_list(f);
            let n = fv.len();
            if !split {
                tiles.push(Tile {
                    face: f as u32,
                    origin: [0.0, 0.0],
                    size: 1.0,
                    corners: [0, 1, 2, 3].map(|i| Corner::Vertex(fv[i])),
                });
                continue;
            }
            let d = (n as Real).sqrt().ceil() as usize;
            for i in 0..n {
                let sub = [
                    Corner::Vertex(fv[i]),
                    Corner::Mid(fe[i]),
                    Corner::Centre(f as u32),
                    Corner::Mid(fe[(i + n - 1) % n]),
                ];
                let (origin, size, corners) = if n == 4 {
                    // A quad's sub-face i in its own (u, v): corner i's quadrant.
                    let c = [[0.0, 0.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]][i];
                    // Rotate the corner list so corner 0 sits at the quadrant's (0, 0).
                    let rot = [[0, 1, 2, 3], [3, 0, 1, 2], [2, 3, 0, 1], [1, 2, 3, 0]][i];
                    (c, 0.5, rot.map(|r| sub[r]))
                } else {
                    ([(i % d) as Real, (i / d) as Real], 0.5, sub)
                };
                tiles.push(Tile {
                    face: f as u32,
                    origin,
                    size,
                    corners,
                });
            }
        }
        // Weld by topological key: a sample shared by several tiles (an edge's,
        // a corner's) is one vertex, evaluated once, in the first tile that
        // has it.
        let mut index: HashMap<Key, u32> = HashMap::new();
        // Per vertex: the tile and grid sample it is evaluated at.
        let mut owner: Vec<(u32, u32)> = Vec::new();
        let mut faces: Vec<Vec<u32>> = Vec::with_capacity(tiles.len() * k * k);
        let mut ids = vec![0u32; (k + 1) * (k + 1)];
        for (t, tile) in tiles.iter().enumerate() {
            for b in 0..=k {
                for a in 0..=k {
                    let sample = b * (k + 1) + a;
                    let mut new = || {
                        owner.push((t as u32, sample as u32));
                        (owner.len() - 1) as u32
                    };
                    ids[sample] = match sample_key(tile, a, b, k) {
                        Some(key) => *index.entry(key).or_insert_with(new),
                        None => new(),
                    };
                }
            }
            for b in 0..k {
                for a in 0..k {
                    let i = |a: usize, b: usize| ids[b * (k + 1) + a];
                    faces.push(vec![i(a, b), i(a + 1, b), i(a + 1, b + 1), i(a, b + 1)]);
                }
            }
        }
        Ok(Tessellation {
            tiles,
            owner,
            faces,
            k,
        })
    }

    /// Every vertex's position and unit normal on `table`; with `keep =
    /// Some((faces, positions, normals))`, only the vertices evaluated on a
    /// tile of a marked control face, the others copied from `positions`
    /// and `normals` (the same surface there).
    pub fn evaluate(
        &self,
        table: &PatchTable,
        keep: Option<(&[bool], &[Point3], &[Vector3])>,
    ) -> Result<(Vec<Point3>, Vec<Vector3>)> {
        let k = self.k;
        Ok(self
            .owner
            .par_iter()
            .enumerate()
            .map(|(i, &(t, sample))| {
                let t = &self.tiles[t as usize];
                if let Some((faces, p, n)) = keep
                    && !faces[t.face as usize]
                {
                    return Ok((p[i], n[i]));
                }
                let (a, b) = (sample as usize % (k + 1), sample as usize / (k + 1));
                let u = t.origin[0] + t.size * a as Real / k as Real;
                let v = t.origin[1] + t.size * b as Real / k as Real;
                let s = table.evaluate(t.face as usize, u, v)?;
                Ok((s.p, s.normal()))
            })
            .collect::<Result<Vec<_>>>()?
            .into_iter()
            .unzip())
    }

    /// The quad mesh of the vertices `positions` (from [`evaluate`](Self::evaluate)).
    pub fn mesh(&self, positions: Vec<Point3>) -> Result<PolyMesh> {
        PolyMesh::from_faces(positions, &self.faces)
    }
}

/// The shared key of grid sample `(a, b)` of a tile, `None` for interior samples.
fn sample_key(t: &Tile, a: usize, b: usize, k: usize) -> Option<Key> {
    let c = &t.corners;
    let corner = match (a, b) {
        (0, 0) => Some(c[0]),
        (x, 0) if x == k => Some(c[1]),
        (x, y) if x == k && y == k => Some(c[2]),
        (0, y) if y == k => Some(c[3]),
        _ => None,
    };
    if let Some(c) = corner {
        return Some(c.into());
    }
    // (edge from corner p to corner q, steps from p)
    let (p, q, j) = if b == 0 {
        (c[0], c[1], a)
    } else if a == k {
        (c[1], c[2], b)
    } else if b == k {
        (c[3], c[2], a)
    } else if a == 0 {
        (c[0], c[3], b)
    } else {
        return None;
    };
    let (lo, hi, j) = if p < q { (p, q, j) } else { (q, p, k - j) };
    Some(Key::OnEdge((lo, hi), j as u32))
}

/// The limit surface of the control mesh `control` (refined with `options`)
/// as `--limit-out` writes it: [`tessellate`]d `k × k` per quad, then split
/// into triangles ([`split_quads`](crate::mesh::split_quads)) unless
/// `quads`; with one unit normal per vertex.
pub fn limit_surface_mesh(
    control: &PolyMesh,
    options: &crate::subdivision::RefineOptions,
    k: usize,
    quads: bool,
) -> Result<(PolyMesh, Vec<Vector3>)> {
    let refiner = Refiner::new(control, options)?;
    let (surf, normals) = tessellate(&refiner, &control.positions, k)?;
    let surf = if quads {
        surf
    } else {
        crate::mesh::split_quads(&surf)
    };
    Ok((surf, normals))
}
