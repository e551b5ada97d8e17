//! Lattice builders (MacCracken & Joy 1996, §5: "an inventory of lattices and
//! a set of tools to merge and build new lattices"): hexahedra, box grids,
//! extrusion of a polygon mesh, cylinders, and cell-by-cell attachment.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::mesh::PolyMesh;

use super::lattice::Lattice;
use super::topology::LatticeTopology;

/// Faces of a hexahedron with vertices in VTK order (0–3 the bottom loop,
/// 4–7 the top loop, vertex `i + 4` above vertex `i`).
pub const HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

fn hex_polyhedron(h: &[u32; 8]) -> Vec<Vec<u32>> {
    HEX_FACES
        .iter()
        .map(|f| f.iter().map(|&i| h[i]).collect())
        .collect()
}

/// A lattice of hexahedra given by their eight vertices in VTK order.
pub fn hexahedra(positions: Vec<Point3>, hexes: &[[u32; 8]]) -> Result<Lattice> {
    let cells: Vec<Vec<Vec<u32>>> = hexes.iter().map(hex_polyhedron).collect();
    let topo = LatticeTopology::from_polyhedra(positions.len(), &cells)?;
    Lattice::new(positions, topo)
}

/// The box `[lo, hi]` as an `nx × ny × nz` grid of equal hexahedra; vertex
/// `(i, j, k)` has index `i + (nx + 1) (j + (ny + 1) k)`.
pub fn box_grid(lo: Point3, hi: Point3, n: [usize; 3]) -> Result<Lattice> {
    if n.iter().any(|&k| k == 0 || k > 1024) {
        return Err(Error::input(format!(
            "box grid of {n:?} cells: each count must be 1 to 1024"
        )));
    }
    if (0..3).any(|k| (hi[k] - lo[k]).is_nan() || hi[k] - lo[k] <= 0.0) {
        return Err(Error::input(format!(
            "box grid: the corners {:?} and {:?} do not span a box",
            lo.coords.as_slice(),
            hi.coords.as_slice()
        )));
    }
    let [nx, ny, nz] = n;
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut positions = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let t = Vector3::new(
                    i as Real / nx as Real,
                    j as Real / ny as Real,
                    k as Real / nz as Real,
                );
                positions.push(lo + (hi - lo).component_mul(&t));
            }
        }
    }
    let mut hexes = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                hexes.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    hexahedra(positions, &hexes)
}

/// Extrudes a polygon mesh `layers` times by `direction` (MacCracken & Joy
/// 1996, §5: "the extrusion tool takes a mesh and extrudes it in a specified
/// direction to become a lattice"): every `k`-gon becomes a prism cell per
/// layer (a hexahedron for a quad). Vertex `v` of layer `l` has index
/// `v + l · mesh.num_vertices()`.
pub fn extrude(mesh: &PolyMesh, direction: Vector3, layers: usize) -> Result<Lattice> {
    if layers == 0 || layers > 4096 {
        return Err(Error::input(format!(
            "extrude: {layers} layers (expected 1 to 4096)"
        )));
    }
    if direction.norm().is_nan() || direction.norm() <= 0.0 || !direction.norm().is_finite() {
        return Err(Error::input("extrude: the direction has no length"));
    }
    let nv = mesh.num_vertices();
    let mut positions = Vec::with_capacity(nv * (layers + 1));
    for l in 0..=layers {
        positions.extend(mesh.positions.iter().map(|p| p + direction * l as Real));
    }
    let mut cells = Vec::with_capacity(mesh.num_faces() * layers);
    for l in 0..layers {
        let (lo, hi) = ((l * nv) as u32, ((l + 1) * nv) as u32);
        for f in mesh.faces() {
            let k = f.len();
            let mut cell = vec![
                f.iter().rev().map(|&v| v + lo).collect::<Vec<u32>>(),
                f.iter().map(|&v| v + hi).collect(),
            ];
            for i in 0..k {
                let (a, b) = (f[i], f[(i + 1) % k]);
                cell.push(vec![a + lo, b + lo, b + hi, a + hi]);
            }
            cells.push(cell);
        }
    }
    let topo = LatticeTopology::from_polyhedra(positions.len(), &cells)?;
    Lattice::new(positions, topo)
}

/// A cylinder lattice along `z` from `z = 0` to `height`: a central
/// `segments`-gon prism column surrounded by a ring of `segments` hexahedra,
/// extruded in `layers` layers (the central cells are not hexahedra unless
/// `segments = 4`). The inner ring has radius `radius / 2`.
pub fn cylinder(radius: Real, height: Real, segments: usize, layers: usize) -> Result<Lattice> {
    let positive = |x: Real| x.is_finite() && x > 0.0;
    if !(3..=256).contains(&segments) || !positive(radius) || !positive(height) {
        return Err(Error::input(format!(
            "cylinder: radius {radius}, height {height}, {segments} segments (need positive sizes and 3 to 256 segments)"
        )));
    }
    let mut pos = Vec::with_capacity(2 * segments);
    for ring in [0.5, 1.0] {
        for s in 0..segments {
            let a = std::f64::consts::TAU * s as Real / segments as Real;
            pos.push(Point3::new(
                ring * radius * a.cos(),
                ring * radius * a.sin(),
                0.0,
            ));
        }
    }
    let n = segments as u32;
    let mut faces = vec![(0..n).collect::<Vec<u32>>()];
    for s in 0..n {
        let t = (s + 1) % n;
        faces.push(vec![s, n + s, n + t, t]);
    }
    let disc = PolyMesh::from_faces(pos, &faces)?;
    extrude(
        &disc,
        Vector3::new(0.0, 0.0, height / layers.max(1) as Real),
        layers,
    )
}

/// Builds a lattice cell by cell (MacCracken & Joy 1996, §5: "the user is
/// allowed to create cells one by one, attaching them face by face").
#[derive(Clone, Debug, Default)]
pub struct LatticeBuilder {
    /// Positions so far.
    pub positions: Vec<Point3>,
    /// Cells so far, each a list of vertex loops.
    pub cells: Vec<Vec<Vec<u32>>>,
}

impl LatticeBuilder {
    /// Adds a vertex and returns its index.
    pub fn add_vertex(&mut self, p: Point3) -> u32 {
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }

    /// Adds a cell given as vertex loops of existing vertices.
    pub fn add_cell(&mut self, faces: Vec<Vec<u32>>) {
        self.cells.push(faces);
    }

    /// Adds a hexahedron (VTK order).
    pub fn add_hexahedron(&mut self, h: [u32; 8]) {
        self.cells.push(hex_polyhedron(&h));
    }

    /// Attaches a prism cell onto the face `face` (a vertex loop of existing
    /// vertices) by copying its vertices moved by `offset`; returns the new
    /// face opposite `face`, onto which the next cell can be attached.
    pub fn attach_cell(&mut self, face: &[u32], offset: Vector3) -> Result<Vec<u32>> {
        if let Some(&v) = face.iter().find(|&&v| v as usize >= self.positions.len()) {
            return Err(Error::out_of_range(format!(
                "attach: vertex {v} does not exist"
            )));
        }
        let top: Vec<u32> = face
            .iter()
            .map(|&v| {
                let p = self.positions[v as usize] + offset;
                self.add_vertex(p)
            })
            .collect();
        let k = face.len();
        let mut cell = vec![face.to_vec(), top.iter().rev().copied().collect()];
        for i in 0..k {
            let j = (i + 1) % k;
            cell.push(vec![face[j], face[i], top[i], top[j]]);
        }
        self.cells.push(cell);
        Ok(top)
    }

    /// The lattice, after every check of [`LatticeTopology::new`] and [`Lattice::new`].
    pub fn build(self) -> Result<Lattice> {
        let topo = LatticeTopology::from_polyhedra(self.positions.len(), &self.cells)?;
        Lattice::new(self.positions, topo)
    }
}
