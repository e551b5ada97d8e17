//! Topology edits of a solid's control lattice (McDonnell & Qin, §5.4,
//! figs. 8–9): extrude a boundary face into a new cell along its normal, and
//! trim (remove) a cell.
//!
//! The lattice functions keep every surviving vertex, face and cell in its
//! order, so extruding a face and then trimming the new cell gives back the
//! same topology. Boundary tags are recomputed automatically
//! ([`BoundaryTags::automatic`]). On a [`Solid`] an edit rebuilds
//! everything below the control lattice (hierarchy, `A`, springs from the
//! rest shape, masses, partition); control-point positions, velocities, rest
//! positions and fixed flags carry over, and ropes re-attach to the mass
//! point nearest their old one.

use crate::error::{Error, Result};
use crate::lattice::{BoundaryTags, Lattice, LatticeTopology, cell_volume};
use crate::math::{Point3, Real, Vector3, newell_normal};

use super::model::Solid;

/// The lattice with a prism cell added on boundary face `face`: its vertices
/// copied and moved by `offset`. Returns the topology and the copied
/// vertices (new vertex `n + i` is a copy of `base[i]`, `n` the old count).
pub fn extruded_topology(
    topo: &LatticeTopology,
    face: usize,
) -> Result<(LatticeTopology, Vec<u32>)> {
    if face >= topo.num_faces() || !topo.is_boundary_face(face) {
        return Err(Error::out_of_range(format!(
            "extrude: face {face} is not a boundary face of the control lattice ({} faces)",
            topo.num_faces()
        )));
    }
    let n = topo.num_vertices as u32;
    let base = topo.faces.row(face).to_vec();
    let k = base.len();
    let mut faces: Vec<Vec<u32>> = (0..topo.num_faces())
        .map(|f| topo.faces.row(f).to_vec())
        .collect();
    let mut cells: Vec<Vec<u32>> = (0..topo.num_cells())
        .map(|c| topo.cells.row(c).to_vec())
        .collect();
    let first = faces.len() as u32;
    faces.push((0..k as u32).map(|i| n + i).collect());
    for i in 0..k {
        let j = (i + 1) % k;
        faces.push(vec![base[i], base[j], n + j as u32, n + i as u32]);
    }
    let mut cell = vec![face as u32];
    cell.extend(first..first + k as u32 + 1);
    cells.push(cell);
    Ok((
        LatticeTopology::new(topo.num_vertices + k, &faces, &cells)?,
        base,
    ))
}

/// Offset of an extrusion of boundary face `face`: its outward unit normal
/// (Newell's method, oriented away from its cell's centroid) times the
/// cell's height over the face, `volume / area`.
pub fn extrusion_offset(
    positions: &[Point3],
    topo: &LatticeTopology,
    face: usize,
) -> Result<Vector3> {
    let l = topo.faces.row(face);
    let mut normal = newell_normal(positions, l);
    let centre = l
        .iter()
        .fold(Vector3::zeros(), |s, &v| s + positions[v as usize].coords)
        / l.len() as Real;
    let area = 0.5 * normal.norm();
    let cell = topo.face_cells[face][0] as usize;
    let vs = topo.cell_vertices.row(cell);
    let cell_centre = vs
        .iter()
        .fold(Vector3::zeros(), |s, &v| s + positions[v as usize].coords)
        / vs.len() as Real;
    if normal.dot(&(centre - cell_centre)) < 0.0 {
        normal = -normal;
    }
    let height = cell_volume(positions, topo, cell)? / area;
    if !(area > 0.0 && height.is_finite() && height > 0.0) {
        return Err(Error::Topology(format!(
            "extrude: face {face} is degenerate (area {area:.3e})"
        )));
    }
    Ok(normal.normalize() * height)
}

/// Extrudes boundary face `face` of a lattice into a new cell along its normal.
pub fn extrude_face(lattice: &Lattice, face: usize) -> Result<Lattice> {
    let (topo, base) = extruded_topology(&lattice.topology, face)?;
    let offset = extrusion_offset(&lattice.positions, &lattice.topology, face)?;
    let mut positions = lattice.positions.clone();
    positions.extend(base.iter().map(|&v| lattice.positions[v as usize] + offset));
    Lattice::new(positions, topo)
}

/// The lattice without cell `cell`; faces and vertices no other cell uses go
/// too. Returns the topology and, for every old vertex, its new index.
pub fn trimmed_topology(
    topo: &LatticeTopology,
    cell: usize,
) -> Result<(LatticeTopology, Vec<Option<u32>>)> {
    if cell >= topo.num_cells() {
        return Err(Error::out_of_range(format!(
            "trim: cell {cell} does not exist ({} cells)",
            topo.num_cells()
        )));
    }
    if topo.num_cells() == 1 {
        return Err(Error::input("trim: cannot remove the only cell"));
    }
    let keep_cells: Vec<usize> = (0..topo.num_cells()).filter(|&c| c != cell).collect();
    let mut face_map = vec![None; topo.num_faces()];
    let mut vert_map = vec![None; topo.num_vertices];
    let mut faces = Vec::new();
    for (f, slot) in face_map.iter_mut().enumerate() {
        let cells_of_f = topo.face_cells[f];
        if cells_of_f
            .iter()
            .any(|&c| c != crate::lattice::NO_CELL && c as usize != cell)
        {
            *slot = Some(faces.len() as u32);
            faces.push(f);
        }
    }
    for &f in &faces {
        for &v in topo.faces.row(f) {
            vert_map[v as usize] = Some(0);
        }
    }
    let mut next = 0u32;
    for m in vert_map.iter_mut().filter(|m| m.is_some()) {
        *m = Some(next);
        next += 1;
    }
    let face_loops: Vec<Vec<u32>> = faces
        .iter()
        .map(|&f| {
            topo.faces
                .row(f)
                .iter()
                .filter_map(|&v| vert_map[v as usize])
                .collect()
        })
        .collect();
    let cells: Vec<Vec<u32>> = keep_cells
        .iter()
        .map(|&c| {
            topo.cells
                .row(c)
                .iter()
                .filter_map(|&f| face_map[f as usize])
                .collect()
        })
        .collect();
    Ok((
        LatticeTopology::new(next as usize, &face_loops, &cells)?,
        vert_map,
    ))
}

/// Removes cell `cell` from a lattice.
pub fn trim_cell(lattice: &Lattice, cell: usize) -> Result<Lattice> {
    let (topo, map) = trimmed_topology(&lattice.topology, cell)?;
    let positions = keep(&lattice.positions, &map);
    Lattice::new(positions, topo)
}

fn keep<T: Copy>(values: &[T], map: &[Option<u32>]) -> Vec<T> {
    values
        .iter()
        .zip(map)
        .filter(|(_, m)| m.is_some())
        .map(|(v, _)| *v)
        .collect()
}

impl Solid {
    /// Extrudes boundary face `face` of the control lattice (current shape
    /// and rest shape each along their own normal); new control points move
    /// with the velocity of the points they were copied from and are free.
    /// On error the solid is left unchanged.
    pub fn extrude(&mut self, face: usize) -> Result<()> {
        let backup = self.clone();
        let result = self.extrude_unchecked(face);
        if result.is_err() {
            *self = backup;
        }
        result
    }

    fn extrude_unchecked(&mut self, face: usize) -> Result<()> {
        let topo = &self.control.topology;
        let (new_topo, base) = extruded_topology(topo, face)?;
        let off = extrusion_offset(&self.p, topo, face)?;
        let off_rest = extrusion_offset(&self.p_rest, topo, face)?;
        for &b in &base {
            let b = b as usize;
            self.p.push(self.p[b] + off);
            self.p_rest.push(self.p_rest[b] + off_rest);
            self.v.push(self.v[b]);
            self.fixed.push(false);
        }
        self.replace_topology(new_topo)
    }

    /// Removes cell `cell` of the control lattice. On error the solid is
    /// left unchanged.
    pub fn trim(&mut self, cell: usize) -> Result<()> {
        let backup = self.clone();
        let result = self.trim_unchecked(cell);
        if result.is_err() {
            *self = backup;
        }
        result
    }

    fn trim_unchecked(&mut self, cell: usize) -> Result<()> {
        let (new_topo, map) = trimmed_topology(&self.control.topology, cell)?;
        self.p = keep(&self.p, &map);
        self.p_rest = keep(&self.p_rest, &map);
        self.v = keep(&self.v, &map);
        self.fixed = keep(&self.fixed, &map);
        self.replace_topology(new_topo)
    }

    /// Installs a new control topology and rebuilds everything below it.
    fn replace_topology(&mut self, topo: LatticeTopology) -> Result<()> {
        let anchors: Vec<Point3> = self.ropes.iter().map(|r| self.d[r.point]).collect();
        let tags = BoundaryTags::automatic(&topo);
        self.control = Lattice::with_tags(self.p_rest.clone(), topo, tags)?;
        self.rebuild_all()?;
        for (i, a) in anchors.iter().enumerate() {
            self.ropes[i].point = self.nearest_mass_point(a);
        }
        Ok(())
    }
}
