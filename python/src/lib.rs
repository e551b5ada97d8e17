//! `subdyn._subdyn`: the Rust half of the Python package `subdyn`. Every
//! function takes and returns numpy arrays (meshes as vertices plus flat
//! face lists with offsets, which the pure-Python layer `subdyn/__init__.py`
//! turns into lists of faces), releases the GIL while the library works, and
//! turns `subdyn::Error` into `OSError` (files) or `ValueError` (bad input)
//! with the library's one-line message.

use pyo3::prelude::*;

mod arrays;
mod fit;
mod io;
mod options;
mod recover;
mod surface;

/// The extension module.
#[pymodule]
fn _subdyn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(recover::recover, m)?)?;
    m.add_function(wrap_pyfunction!(surface::subdivide, m)?)?;
    m.add_function(wrap_pyfunction!(io::read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(io::read_points, m)?)?;
    m.add_function(wrap_pyfunction!(io::write_mesh, m)?)?;
    m.add_class::<surface::LimitSurface>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
