//! `subdivide` and `LimitSurface`: uniform refinement, exact limit
//! evaluation and limit-stencil Jacobians of a control mesh.

use numpy::ndarray::Array3;
use numpy::{PyArray1, PyArray3, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use subdyn::limit::{LimitEvaluator, Sample, limit_surface_mesh};
use subdyn::math::Point3;
use subdyn::mesh::{PolyMesh, split_quads};
use subdyn::subdivision::{RefineOptions, Refiner, check_uniform_size, uniform_positions};

use crate::arrays::{
    MeshArrays, mesh, mesh_arrays, py_err, value_error, vector_array, without_gil,
};

/// Refinement options from the `creases` array (rows `i j s`) and the
/// boundary rule's CLI spelling (`edge-and-corner`, `edge-only`).
pub fn refine_options(
    creases: Option<&PyReadonlyArray2<'_, f64>>,
    boundary: &str,
) -> PyResult<RefineOptions> {
    let boundary = boundary.parse().map_err(py_err)?;
    let mut list = Vec::new();
    if let Some(c) = creases {
        let a = c.as_array();
        if a.ncols() != 3 {
            return Err(value_error(format!(
                "creases must be an (m, 3) array of rows (i, j, sharpness), got shape ({}, {})",
                a.nrows(),
                a.ncols()
            )));
        }
        for (r, row) in a.rows().into_iter().enumerate() {
            let index = |x: f64| {
                (x >= 0.0 && x.fract() == 0.0 && x <= u32::MAX as f64)
                    .then_some(x as u32)
                    .ok_or_else(|| value_error(format!("crease {r}: {x} is not a vertex index")))
            };
            list.push((index(row[0])?, index(row[1])?, row[2]));
        }
    }
    Ok(RefineOptions {
        boundary,
        creases: list,
        ..Default::default()
    })
}

/// Uniform Catmull-Clark refinement to `levels` (at most 8); with `limit`
/// the vertices are moved to the limit surface and the faces are triangles
/// unless `quads` (as `subdyn subdivide`).
#[pyfunction]
#[pyo3(signature = (vertices, face_vertices, face_offsets, levels, creases=None, boundary="edge-and-corner", limit=false, quads=false))]
#[allow(clippy::too_many_arguments)]
pub fn subdivide<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    face_vertices: PyReadonlyArray1<'py, i64>,
    face_offsets: PyReadonlyArray1<'py, i64>,
    levels: usize,
    creases: Option<PyReadonlyArray2<'py, f64>>,
    boundary: &str,
    limit: bool,
    quads: bool,
) -> PyResult<MeshArrays<'py>> {
    let m = mesh(&vertices, &face_vertices, &face_offsets)?;
    let options = refine_options(creases.as_ref(), boundary)?;
    let out = without_gil(py, None, || {
        check_uniform_size(&m, levels, limit)?;
        let h = Refiner::new(&m, &options)?.refine_uniform(levels)?;
        let p = uniform_positions(&h, &m.positions, levels, limit)?;
        let out = h.mesh(levels, p);
        Ok(if limit && !quads {
            split_quads(&out)
        } else {
            out
        })
    })?;
    Ok(mesh_arrays(py, &out))
}

/// The exact Catmull-Clark limit surface of a control mesh.
#[pyclass(module = "subdyn._subdyn", frozen)]
pub struct LimitSurface {
    mesh: PolyMesh,
    options: RefineOptions,
    boundary: String,
    evaluator: LimitEvaluator,
}

#[pymethods]
impl LimitSurface {
    #[new]
    #[pyo3(signature = (vertices, face_vertices, face_offsets, creases=None, boundary="edge-and-corner"))]
    fn new(
        vertices: PyReadonlyArray2<'_, f64>,
        face_vertices: PyReadonlyArray1<'_, i64>,
        face_offsets: PyReadonlyArray1<'_, i64>,
        creases: Option<PyReadonlyArray2<'_, f64>>,
        boundary: &str,
    ) -> PyResult<Self> {
        let mesh = mesh(&vertices, &face_vertices, &face_offsets)?;
        let options = refine_options(creases.as_ref(), boundary)?;
        let refiner = Refiner::new(&mesh, &options).map_err(py_err)?;
        Ok(LimitSurface {
            evaluator: LimitEvaluator::new(&refiner),
            mesh,
            options,
            boundary: boundary.to_string(),
        })
    }

    /// Number of control points.
    #[getter]
    fn num_control_points(&self) -> usize {
        self.evaluator.num_control_points()
    }

    /// Number of faces of the control mesh.
    #[getter]
    fn num_faces(&self) -> usize {
        self.evaluator.num_faces()
    }

    /// Positions and derivatives at the samples: a `(6, n, 3)` array of
    /// `P, Pu, Pv, Puu, Puv, Pvv`.
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        face: PyReadonlyArray1<'py, i64>,
        u: PyReadonlyArray1<'py, f64>,
        v: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let samples = samples(&face, &u, &v)?;
        let n = samples.len();
        let rows = without_gil(py, None, || {
            let t = self.evaluator.stencils(&samples)?;
            [&t.p, &t.du, &t.dv, &t.duu, &t.duv, &t.dvv]
                .iter()
                .map(|table| table.apply(&self.mesh.positions))
                .collect::<subdyn::Result<Vec<Vec<Point3>>>>()
        })?;
        let flat: Vec<f64> = rows
            .iter()
            .flatten()
            .flat_map(|p| [p.x, p.y, p.z])
            .collect();
        let a = Array3::from_shape_vec((6, n, 3), flat)
            .map_err(|e| value_error(format!("internal shape error: {e}")))?;
        Ok(PyArray3::from_owned_array(py, a))
    }

    /// The limit stencils of one quantity (`p`, `du`, `dv`, `duu`, `duv`,
    /// `dvv`) at the samples as CSR arrays `(data, indices, indptr, shape)`:
    /// row `i` holds the weights of the control points in sample `i`.
    #[pyo3(signature = (face, u, v, derivative="p"))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        face: PyReadonlyArray1<'py, i64>,
        u: PyReadonlyArray1<'py, f64>,
        v: PyReadonlyArray1<'py, f64>,
        derivative: &str,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let which = ["p", "du", "dv", "duu", "duv", "dvv"]
            .iter()
            .position(|&d| d == derivative)
            .ok_or_else(|| {
                value_error(format!(
                    "derivative '{derivative}' is not one of p, du, dv, duu, duv, dvv"
                ))
            })?;
        let samples = samples(&face, &u, &v)?;
        let table = without_gil(py, None, || {
            let t = self.evaluator.stencils(&samples)?;
            let [p, du, dv, duu, duv, dvv] = [t.p, t.du, t.dv, t.duu, t.duv, t.dvv];
            Ok(match which {
                0 => p,
                1 => du,
                2 => dv,
                3 => duu,
                4 => duv,
                _ => dvv,
            })
        })?;
        let (mut data, mut indices, mut indptr) = (Vec::new(), Vec::new(), vec![0i64]);
        for r in 0..table.num_rows() {
            let (cols, w) = table.row(r);
            indices.extend(cols.iter().map(|&c| c as i64));
            data.extend_from_slice(w);
            indptr.push(indices.len() as i64);
        }
        let shape = (table.num_rows(), self.evaluator.num_control_points());
        (
            PyArray1::from_vec(py, data),
            PyArray1::from_vec(py, indices),
            PyArray1::from_vec(py, indptr),
            shape,
        )
            .into_pyobject(py)
    }

    /// The limit surface tessellated `k × k` per quad: `(vertices,
    /// face_vertices, face_offsets, normals)`, triangles unless `quads`.
    #[pyo3(signature = (k=4, quads=false))]
    fn tessellate<'py>(
        &self,
        py: Python<'py>,
        k: usize,
        quads: bool,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (surf, normals) = without_gil(py, None, || {
            limit_surface_mesh(&self.mesh, &self.options, k, quads)
        })?;
        let (v, fv, fo) = mesh_arrays(py, &surf);
        (v, fv, fo, vector_array(py, &normals)).into_pyobject(py)
    }

    /// The arguments that rebuild this surface (for pickle).
    fn __getnewargs__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let (v, fv, fo) = mesh_arrays(py, &self.mesh);
        let creases: Vec<f64> = self
            .options
            .creases
            .iter()
            .flat_map(|&(i, j, s)| [i as f64, j as f64, s])
            .collect();
        let creases = PyArray1::from_vec(py, creases).reshape([self.options.creases.len(), 3])?;
        (v, fv, fo, creases, self.boundary.clone()).into_pyobject(py)
    }
}

/// Samples from three equally long arrays.
fn samples(
    face: &PyReadonlyArray1<'_, i64>,
    u: &PyReadonlyArray1<'_, f64>,
    v: &PyReadonlyArray1<'_, f64>,
) -> PyResult<Vec<Sample>> {
    let (f, u, v) = (face.as_array(), u.as_array(), v.as_array());
    if f.len() != u.len() || f.len() != v.len() {
        return Err(value_error(format!(
            "face, u and v must have the same length, got {}, {} and {}",
            f.len(),
            u.len(),
            v.len()
        )));
    }
    f.iter()
        .zip(u.iter().zip(v.iter()))
        .map(|(&face, (&u, &v))| {
            let face = u32::try_from(face)
                .map_err(|_| value_error(format!("face {face} is not a valid face index")))?;
            Ok(Sample { face, u, v })
        })
        .collect()
}
