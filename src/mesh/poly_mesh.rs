//! `PolyMesh`: positions plus faces of any size in compressed-row form.

use crate::error::{Error, Result};
use crate::math::{Point3, first_non_finite};

/// A polygon mesh: vertex positions and faces of any size (CSR).
///
/// Face `f` has the vertices `face_vertices[face_offsets[f]..face_offsets[f + 1]]`,
/// counter-clockwise seen from outside. Indices are 0-based.
///
/// ```
/// use subdyn::mesh::PolyMesh;
/// use subdyn::math::Point3;
/// let quad = PolyMesh::from_faces(
///     vec![Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0),
///          Point3::new(1.0, 1.0, 0.0), Point3::new(0.0, 1.0, 0.0)],
///     &[vec![0, 1, 2, 3]],
/// ).unwrap();
/// assert_eq!(quad.num_faces(), 1);
/// assert_eq!(quad.face(0), &[0, 1, 2, 3]);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolyMesh {
    /// Vertex positions.
    pub positions: Vec<Point3>,
    /// `num_faces + 1` offsets into `face_vertices`, starting at 0.
    pub face_offsets: Vec<u32>,
    /// Concatenated vertex indices of all faces.
    pub face_vertices: Vec<u32>,
}

impl PolyMesh {
    /// Builds a mesh from positions and a list of faces, checking that every
    /// index is in range, every face has at least three vertices and every
    /// coordinate is finite.
    pub fn from_faces(positions: Vec<Point3>, faces: &[Vec<u32>]) -> Result<Self> {
        let mut face_offsets = Vec::with_capacity(faces.len() + 1);
        face_offsets.push(0u32);
        let mut face_vertices = Vec::new();
        for f in faces {
            face_vertices.extend_from_slice(f);
            face_offsets.push(face_vertices.len() as u32);
        }
        let mesh = PolyMesh {
            positions,
            face_offsets,
            face_vertices,
        };
        mesh.validate()?;
        Ok(mesh)
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }

    /// Vertex indices of face `f`.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_vertices[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// Iterator over all faces.
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        (0..self.num_faces()).map(move |f| self.face(f))
    }

    /// Checks finite coordinates, face sizes (≥ 3) and index ranges; the error
    /// names the first offending vertex or face.
    pub fn validate(&self) -> Result<()> {
        check_finite(&self.positions)?;
        if self.face_offsets.first().copied().unwrap_or(0) != 0
            || self.face_offsets.last().copied().unwrap_or(0) as usize != self.face_vertices.len()
        {
            return Err(Error::input("face offsets do not match face vertices"));
        }
        let n = self.positions.len();
        for (f, face) in self.faces().enumerate() {
            if face.len() < 3 {
                return Err(Error::Topology(format!(
                    "face {f} has {} vertices; a face needs at least 3",
                    face.len()
                )));
            }
            if let Some(&bad) = face.iter().find(|&&v| v as usize >= n) {
                return Err(Error::Topology(format!(
                    "face {f} refers to vertex {bad}, but the mesh has only {n} vertices"
                )));
            }
        }
        Ok(())
    }
}

/// Checks that every coordinate is finite; the error names the first bad vertex.
pub(crate) fn check_finite(points: &[Point3]) -> Result<()> {
    match first_non_finite(points) {
        Some(i) => Err(Error::non_finite(format!(
            "vertex {i} has a non-finite coordinate ({}, {}, {})",
            points[i].x, points[i].y, points[i].z
        ))),
        None => Ok(()),
    }
}

impl PolyMesh {
    /// The meshes side by side in one, in order (the second's vertex `i` is
    /// `i` plus the first's vertex count, and so on): a control mesh of
    /// several parts.
    ///
    /// ```
    /// let cube = subdyn::examples::cube();
    /// let two = subdyn::mesh::PolyMesh::disjoint_union(&[cube.clone(), cube.clone()]);
    /// assert_eq!((two.num_vertices(), two.num_faces()), (16, 12));
    /// assert_eq!(two.face(6), &cube.face(0).iter().map(|v| v + 8).collect::<Vec<_>>()[..]);
    /// ```
    pub fn disjoint_union(meshes: &[PolyMesh]) -> PolyMesh {
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
}
