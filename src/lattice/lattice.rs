//! `Lattice`: control-point positions on a [`LatticeTopology`], with the
//! boundary tags (corner vertices, sharp edges) of MacCracken & Joy 1996, §3.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3, bbox_diagonal};

use super::topology::{LatticeTopology, NO_CELL};

/// Corner vertices and sharp edges, which the boundary rules treat specially
/// (MacCracken & Joy 1996, §3).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BoundaryTags {
    /// `corners[v]`: vertex `v` never moves under refinement.
    pub corners: Vec<bool>,
    /// `sharp_edges[e]`: edge `e` is refined as a uniform cubic B-spline curve.
    pub sharp_edges: Vec<bool>,
}

impl BoundaryTags {
    /// The automatic marking. MacCracken & Joy call a vertex a corner when it
    /// is "incident to only one cell", and an edge sharp when it joins
    /// vertices "incident to only one or two cells". We read the sharp-edge
    /// rule per edge: a boundary edge is sharp when it lies in exactly one
    /// cell (the edges of a box, the rims of an extruded cylinder) or when it
    /// does not have exactly two boundary faces (a non-manifold boundary).
    /// On box grids and extruded meshes both readings agree except for the
    /// cross edges of one-cell-thick bars, which are straight either way; the
    /// per-edge reading does not mark an edge whose endpoints happen to lie on
    /// two different box edges. A boundary vertex with three or more sharp
    /// edges is a corner too (it cannot be on one B-spline curve).
    pub fn automatic(topo: &LatticeTopology) -> BoundaryTags {
        let sharp_edges: Vec<bool> = (0..topo.num_edges())
            .map(|e| {
                let bfaces = topo
                    .edge_faces
                    .row(e)
                    .iter()
                    .filter(|&&f| topo.face_cells[f as usize][1] == NO_CELL)
                    .count();
                bfaces > 0 && (topo.edge_cells.row(e).len() == 1 || bfaces != 2)
            })
            .collect();
        let corners = (0..topo.num_vertices)
            .map(|v| {
                let sharp = topo
                    .vertex_edges
                    .row(v)
                    .iter()
                    .filter(|&&e| sharp_edges[e as usize])
                    .count();
                topo.vertex_cells.row(v).len() == 1 || sharp >= 3
            })
            .collect();
        BoundaryTags {
            corners,
            sharp_edges,
        }
    }

    /// Checks the sizes against a topology.
    pub fn check(&self, topo: &LatticeTopology) -> Result<()> {
        if self.corners.len() != topo.num_vertices || self.sharp_edges.len() != topo.num_edges() {
            return Err(Error::size_mismatch(format!(
                "boundary tags for {} vertices and {} edges, but the lattice has {} and {}",
                self.corners.len(),
                self.sharp_edges.len(),
                topo.num_vertices,
                topo.num_edges()
            )));
        }
        Ok(())
    }
}

/// A volume lattice: control points, topology and boundary tags.
#[derive(Clone, Debug, PartialEq)]
pub struct Lattice {
    /// Control-point positions, one per topology vertex.
    pub positions: Vec<Point3>,
    /// Vertices, edges, faces, cells.
    pub topology: LatticeTopology,
    /// Corners and sharp edges.
    pub tags: BoundaryTags,
}

impl Lattice {
    /// A lattice with automatic boundary tags, after the geometric checks of
    /// [`check_geometry`].
    pub fn new(positions: Vec<Point3>, topology: LatticeTopology) -> Result<Lattice> {
        let tags = BoundaryTags::automatic(&topology);
        Lattice::with_tags(positions, topology, tags)
    }

    /// A lattice with the given tags, after the geometric checks.
    pub fn with_tags(
        positions: Vec<Point3>,
        topology: LatticeTopology,
        tags: BoundaryTags,
    ) -> Result<Lattice> {
        tags.check(&topology)?;
        check_geometry(&positions, &topology)?;
        Ok(Lattice {
            positions,
            topology,
            tags,
        })
    }

    /// Number of control points.
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// The boundary faces (those of one cell) as a polygon mesh over all the
    /// lattice's positions: the lattice's hull, e.g. to draw it.
    pub fn boundary_mesh(&self) -> Result<crate::mesh::PolyMesh> {
        self.faces_mesh(self.topology.boundary_faces())
    }

    /// Every face, interior ones too, as a polygon mesh over all the
    /// lattice's positions: its edges are the edges of every cell, e.g. to
    /// draw the lattice as a cage.
    pub fn all_faces_mesh(&self) -> Result<crate::mesh::PolyMesh> {
        self.faces_mesh(0..self.topology.num_faces() as u32)
    }

    fn faces_mesh(&self, faces: impl IntoIterator<Item = u32>) -> Result<crate::mesh::PolyMesh> {
        let t = &self.topology;
        let faces: Vec<Vec<u32>> = faces
            .into_iter()
            .map(|f| t.faces.row(f as usize).to_vec())
            .collect();
        crate::mesh::PolyMesh::from_faces(self.positions.clone(), &faces)
    }

    /// Volume of every cell (faces fanned from their centroids, divergence
    /// theorem over the consistently oriented cell surface).
    pub fn cell_volumes(&self) -> Result<Vec<Real>> {
        (0..self.topology.num_cells())
            .map(|c| cell_volume(&self.positions, &self.topology, c))
            .collect()
    }
}

/// Checks that there is one finite position per vertex and that no cell is
/// flat (volume below `1e-12 · diagonal³`) or has faces that cannot be
/// oriented consistently.
pub fn check_geometry(positions: &[Point3], topo: &LatticeTopology) -> Result<()> {
    if positions.len() != topo.num_vertices {
        return Err(Error::size_mismatch(format!(
            "{} positions for a lattice of {} vertices",
            positions.len(),
            topo.num_vertices
        )));
    }
    if let Some(v) = positions
        .iter()
        .position(|p| !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()))
    {
        return Err(Error::input(format!(
            "vertex {v}: coordinate is not a finite number ({:?})",
            positions[v].coords.as_slice()
        )));
    }
    let d = bbox_diagonal(positions);
    for c in 0..topo.num_cells() {
        let vol = cell_volume(positions, topo, c)?;
        if vol.is_nan() || vol <= 1e-12 * d * d * d {
            return Err(Error::Topology(format!(
                "cell {c}: degenerate (volume {vol:.3e}; the lattice diagonal is {d:.3e})"
            )));
        }
    }
    Ok(())
}

/// Unsigned volume of cell `c`: its faces oriented consistently (breadth
/// first over shared edges), each fanned from its centroid, summed as signed
/// tetrahedra against the cell centroid.
pub fn cell_volume(positions: &[Point3], topo: &LatticeTopology, c: usize) -> Result<Real> {
    let faces = topo.cells.row(c);
    let mut flip: Vec<Option<bool>> = vec![None; faces.len()];
    flip[0] = Some(false);
    let mut stack = vec![0usize];
    let directed = |i: usize, flipped: bool| -> Vec<(u32, u32)> {
        let l = topo.faces.row(faces[i] as usize);
        (0..l.len())
            .map(|k| {
                let (a, b) = (l[k], l[(k + 1) % l.len()]);
                if flipped { (b, a) } else { (a, b) }
            })
            .collect()
    };
    while let Some(i) = stack.pop() {
        let mine = directed(i, flip[i].unwrap_or(false));
        #[allow(clippy::needless_range_loop)]
        for j in 0..faces.len() {
            if j == i {
                continue;
            }
            let theirs = directed(j, false);
            let shared = mine.iter().find_map(|&(a, b)| {
                theirs
                    .iter()
                    .find(|&&(x, y)| (x == a && y == b) || (x == b && y == a))
                    .map(|&(x, _)| x == a)
            });
            let Some(same_direction) = shared else {
                continue;
            };
            // Neighbours must run a shared edge in opposite directions.
            let want = same_direction;
            match flip[j] {
                None => {
                    flip[j] = Some(want);
                    stack.push(j);
                }
                Some(f) if f != want => {
                    return Err(Error::Topology(format!(
                        "cell {c}: its faces cannot be oriented consistently"
                    )));
                }
                _ => {}
            }
        }
    }
    let verts = topo.cell_vertices.row(c);
    let centre = verts
        .iter()
        .fold(Vector3::zeros(), |s, &v| s + positions[v as usize].coords)
        / verts.len() as Real;
    let mut vol = 0.0;
    for (i, &f) in faces.iter().enumerate() {
        let l = topo.faces.row(f as usize);
        let fc = l
            .iter()
            .fold(Vector3::zeros(), |s, &v| s + positions[v as usize].coords)
            / l.len() as Real;
        for k in 0..l.len() {
            let (mut a, mut b) = (l[k], l[(k + 1) % l.len()]);
            if flip[i].unwrap_or(false) {
                std::mem::swap(&mut a, &mut b);
            }
            let pa = positions[a as usize].coords - centre;
            let pb = positions[b as usize].coords - centre;
            vol += (fc - centre).dot(&pa.cross(&pb)) / 6.0;
        }
    }
    Ok(vol.abs())
}
