//! `read_mesh`, `read_points`, `write_mesh`: the library's readers and
//! writers (format from the extension, atomic writes).

use std::path::PathBuf;

use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::arrays::{MeshArrays, mesh, mesh_arrays, point_array, py_err, vector_array, vectors};
use crate::surface::refine_options;

/// Reads a mesh (.obj, .ply, .off, .xyz; .gz too).
#[pyfunction]
pub fn read_mesh(py: Python<'_>, path: PathBuf) -> PyResult<MeshArrays<'_>> {
    let m = py.detach(|| subdyn::io::read_mesh(&path)).map_err(py_err)?;
    Ok(mesh_arrays(py, &m))
}

/// Reads the points of any point or mesh file, and their normals if the
/// file has them.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn read_points(
    py: Python<'_>,
    path: PathBuf,
) -> PyResult<(Bound<'_, PyArray2<f64>>, Option<Bound<'_, PyArray2<f64>>>)> {
    let cloud = py
        .detach(|| subdyn::io::read_points(&path))
        .map_err(py_err)?;
    Ok((
        point_array(py, &cloud.positions),
        cloud.normals.as_deref().map(|n| vector_array(py, n)),
    ))
}

/// Writes a mesh (format from the extension) with optional vertex normals,
/// through a temporary file that is renamed, so a failure leaves nothing.
/// A control mesh's `creases` (rows `i j s`) go into an OBJ file as `t
/// crease` lines, or beside any other format as `PATH.creases`; they take
/// no normals.
#[pyfunction]
#[pyo3(signature = (path, vertices, face_vertices, face_offsets, normals=None, creases=None))]
pub fn write_mesh(
    py: Python<'_>,
    path: PathBuf,
    vertices: PyReadonlyArray2<'_, f64>,
    face_vertices: PyReadonlyArray1<'_, i64>,
    face_offsets: PyReadonlyArray1<'_, i64>,
    normals: Option<PyReadonlyArray2<'_, f64>>,
    creases: Option<PyReadonlyArray2<'_, f64>>,
) -> PyResult<()> {
    let m = mesh(&vertices, &face_vertices, &face_offsets)?;
    if let Some(c) = &creases {
        if normals.is_some() {
            return Err(crate::arrays::value_error(
                "creases go with a control mesh, which is written without normals",
            ));
        }
        let tags = refine_options(Some(c), "edge-and-corner")?.creases;
        return py
            .detach(|| subdyn::io::write_control_mesh(&path, &m, &tags))
            .map(|_| ())
            .map_err(py_err);
    }
    let normals = match &normals {
        Some(n) => Some(vectors(n, "normals")?),
        None => None,
    };
    if let Some(n) = &normals
        && n.len() != m.num_vertices()
    {
        return Err(crate::arrays::value_error(format!(
            "{} normals given for {} vertices",
            n.len(),
            m.num_vertices()
        )));
    }
    py.detach(|| subdyn::io::write_mesh(&path, &m, normals.as_deref()))
        .map_err(py_err)
}
