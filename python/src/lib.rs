//! The `deepbrdf` Python module (PyO3): measured BRDFs and DeepBRDF (Hu et al., CGF 2020) from
//! numpy, over the library crates, with no second implementation: every function is the
//! library call the `experiments` command line makes, so results are equal byte for byte.
//! Built by maturin (`pip install ./python`); docs/python.md documents it.
mod arrays;
mod data;
mod errors;
mod model;
mod render;

use pyo3::prelude::*;

/// Measured BRDFs (MERL `.binary`, RGL `.bsdf`, the bundled materials) and the DeepBRDF
/// representation (Hu et al. 2020) from numpy. Tables are float32 arrays of shape
/// (3, 90, 90, 180) in 1/sr with NaN for invalid cells; see `Model` for the representation.
#[pymodule]
fn deepbrdf(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(data::read_merl, m)?)?;
    m.add_function(wrap_pyfunction!(data::write_merl, m)?)?;
    m.add_function(wrap_pyfunction!(data::read_bsdf, m)?)?;
    m.add_function(wrap_pyfunction!(data::write_bsdf, m)?)?;
    m.add_function(wrap_pyfunction!(data::bundled, m)?)?;
    m.add_function(wrap_pyfunction!(data::bundled_names, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::write_png, m)?)?;
    m.add_function(wrap_pyfunction!(render::write_exr, m)?)?;
    m.add_function(wrap_pyfunction!(render::relae, m)?)?;
    m.add_function(wrap_pyfunction!(render::attributes, m)?)?;
    m.add_class::<model::Model>()?;
    m.add("FileFormatError", m.py().get_type::<errors::FileFormatError>())?;
    m.add("DEFAULT_MODEL_DIR", deepbrdf_model::DEFAULT_MODEL_DIR)?;
    Ok(())
}
