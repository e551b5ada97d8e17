//! numpy arrays ⇄ subdyn types, errors ⇄ Python exceptions, and the rayon
//! pool a call runs in.

use numpy::ndarray::Array2;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;

use subdyn::math::{Point3, Vector3};
use subdyn::mesh::PolyMesh;

/// `subdyn::Error` as a Python exception: `OSError` for a file that could
/// not be opened, read or written, `ValueError` for everything else; the
/// message is the library's one line.
pub fn py_err(e: subdyn::Error) -> PyErr {
    match e {
        subdyn::Error::Io { .. } => PyOSError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// A `ValueError` with `message`.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// Rows of an `(n, 3)` float64 array as points; `what` names it in errors.
pub fn points(array: &PyReadonlyArray2<'_, f64>, what: &str) -> PyResult<Vec<Point3>> {
    let a = array.as_array();
    if a.ncols() != 3 {
        return Err(value_error(format!(
            "{what} must be an (n, 3) array, got shape ({}, {})",
            a.nrows(),
            a.ncols()
        )));
    }
    Ok(a.rows()
        .into_iter()
        .map(|r| Point3::new(r[0], r[1], r[2]))
        .collect())
}

/// Rows of an `(n, 3)` float64 array as vectors.
pub fn vectors(array: &PyReadonlyArray2<'_, f64>, what: &str) -> PyResult<Vec<Vector3>> {
    Ok(points(array, what)?.into_iter().map(|p| p.coords).collect())
}

/// A mesh from vertices `(n, 3)`, the flat vertex list of all faces and the
/// offsets where each face starts (one more than the faces), checked.
pub fn mesh(
    vertices: &PyReadonlyArray2<'_, f64>,
    face_vertices: &PyReadonlyArray1<'_, i64>,
    face_offsets: &PyReadonlyArray1<'_, i64>,
) -> PyResult<PolyMesh> {
    let positions = points(vertices, "vertices")?;
    let index = |x: i64, what: &str| {
        u32::try_from(x).map_err(|_| value_error(format!("{what} {x} is not a valid index")))
    };
    let face_vertices = face_vertices
        .as_array()
        .iter()
        .map(|&v| index(v, "face vertex"))
        .collect::<PyResult<Vec<u32>>>()?;
    let face_offsets = face_offsets
        .as_array()
        .iter()
        .map(|&v| index(v, "face offset"))
        .collect::<PyResult<Vec<u32>>>()?;
    if face_offsets.windows(2).any(|w| w[0] > w[1]) {
        return Err(value_error("face offsets must not decrease"));
    }
    let mesh = PolyMesh {
        positions,
        face_offsets,
        face_vertices,
    };
    mesh.validate().map_err(py_err)?;
    Ok(mesh)
}

/// Points (or vectors) as an `(n, 3)` float64 array.
pub fn point_array<'py>(py: Python<'py>, p: &[Point3]) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = p.iter().flat_map(|q| [q.x, q.y, q.z]).collect();
    let a = Array2::from_shape_vec((p.len(), 3), flat).unwrap_or_else(|_| Array2::zeros((0, 3)));
    PyArray2::from_owned_array(py, a)
}

/// Vectors as an `(n, 3)` float64 array.
pub fn vector_array<'py>(py: Python<'py>, v: &[Vector3]) -> Bound<'py, PyArray2<f64>> {
    let p: Vec<Point3> = v.iter().map(|x| Point3::from(*x)).collect();
    point_array(py, &p)
}

/// A mesh as numpy arrays: `(vertices, face_vertices, face_offsets)`.
pub type MeshArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray1<i64>>,
);

/// A mesh as `(vertices, face_vertices, face_offsets)` (int64 indices).
pub fn mesh_arrays<'py>(py: Python<'py>, mesh: &PolyMesh) -> MeshArrays<'py> {
    let fv: Vec<i64> = mesh.face_vertices.iter().map(|&v| v as i64).collect();
    let fo: Vec<i64> = mesh.face_offsets.iter().map(|&v| v as i64).collect();
    (
        point_array(py, &mesh.positions),
        PyArray1::from_vec(py, fv),
        PyArray1::from_vec(py, fo),
    )
}

/// Runs `work` without the GIL, inside a rayon pool of `threads` threads
/// when given (a Ray task's `num_cpus`), else in rayon's global pool.
/// Results do not depend on the thread count.
pub fn without_gil<T: Send>(
    py: Python<'_>,
    threads: Option<usize>,
    work: impl FnOnce() -> subdyn::Result<T> + Send,
) -> PyResult<T> {
    let pool = match threads {
        Some(0) => return Err(value_error("threads must be at least 1")),
        Some(n) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| value_error(format!("cannot start {n} threads: {e}")))?,
        ),
        None => None,
    };
    py.detach(move || match pool {
        Some(pool) => pool.install(work),
        None => work(),
    })
    .map_err(py_err)
}

/// Sharp edges `(i, j, s)` as an `(m, 3)` float64 array (rows as the
/// `creases` argument of `subdivide` and `LimitSurface` take them).
pub fn crease_array<'py>(
    py: Python<'py>,
    creases: &[(u32, u32, f64)],
) -> Bound<'py, PyArray2<f64>> {
    let flat: Vec<f64> = creases
        .iter()
        .flat_map(|&(i, j, s)| [f64::from(i), f64::from(j), s])
        .collect();
    let a =
        Array2::from_shape_vec((creases.len(), 3), flat).unwrap_or_else(|_| Array2::zeros((0, 3)));
    PyArray2::from_owned_array(py, a)
}
