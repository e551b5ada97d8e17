//! `RawGeometry`: what every reader produces before it becomes a
//! [`PolyMesh`] or a [`PointCloud`] — positions, optional normals and faces in
//! compressed-row form, with each face checked as it is closed.

use std::path::Path;

use crate::error::{Error, Result};
use crate::math::{Point3, Vector3};
use crate::mesh::{PointCloud, PolyMesh};

/// Positions, optional per-vertex normals and faces (CSR) read from one file.
///
/// Readers check coordinates (finite) and face indices (in range) while they
/// parse, where they still know the line; [`RawGeometry::close_face`] checks
/// face sizes. The conversions then only check that there are vertices.
#[derive(Debug)]
pub(crate) struct RawGeometry {
    /// Vertex positions, all finite.
    pub positions: Vec<Point3>,
    /// One normal per vertex, when the file has them.
    pub normals: Option<Vec<Vector3>>,
    /// `num_faces + 1` offsets into `face_vertices`, starting at 0.
    pub face_offsets: Vec<u32>,
    /// Concatenated 0-based vertex indices of all faces.
    pub face_vertices: Vec<u32>,
}

impl RawGeometry {
    /// No vertices, no normals, no faces.
    pub fn new() -> Self {
        RawGeometry {
            positions: Vec::new(),
            normals: None,
            face_offsets: vec![0],
            face_vertices: Vec::new(),
        }
    }

    /// Ends the face whose indices were pushed onto `face_vertices` since the
    /// last call; `face` (0-based) and `line` name it in errors.
    pub fn close_face(&mut self, path: &Path, line: usize, face: usize) -> Result<()> {
        let start = self.face_offsets.last().copied().unwrap_or(0) as usize;
        let size = self.face_vertices.len() - start;
        if size < 3 {
            return Err(Error::parse(
                path,
                line,
                format!("face {face} has {size} vertices; a face needs at least 3"),
            ));
        }
        let end = u32::try_from(self.face_vertices.len())
            .map_err(|_| Error::parse(path, line, "more than 2^32 face indices in one mesh"))?;
        self.face_offsets.push(end);
        Ok(())
    }

    /// The mesh; an error when the file had no vertices.
    pub fn into_mesh(self, path: &Path) -> Result<PolyMesh> {
        self.check_vertices(path)?;
        let mesh = PolyMesh {
            positions: self.positions,
            face_offsets: self.face_offsets,
            face_vertices: self.face_vertices,
        };
        debug_assert!(mesh.validate().is_ok());
        Ok(mesh)
    }

    /// The points and their normals (faces are dropped); an error when the
    /// file had no vertices.
    pub fn into_cloud(self, path: &Path) -> Result<PointCloud> {
        self.check_vertices(path)?;
        PointCloud::new(self.positions, self.normals)
    }

    /// Fails when there is no vertex or more than `u32` can index.
    fn check_vertices(&self, path: &Path) -> Result<()> {
        if self.positions.is_empty() {
            return Err(Error::parse(path, 0, "the file has no vertices"));
        }
        if u32::try_from(self.positions.len()).is_err() {
            return Err(Error::parse(path, 0, "more than 2^32 vertices in one file"));
        }
        Ok(())
    }
}
