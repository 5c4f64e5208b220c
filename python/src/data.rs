//! Reading and writing measured BRDFs from Python: MERL `.binary` files, RGL `.bsdf`
//! measurements tabulated on the MERL grid and tables exported as `.bsdf` files, the bundled
//! materials (`deepbrdf_data`).
use crate::arrays::{table_in, table_out};
use crate::errors::{py_err, value_error};
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::cache::Cache;
use deepbrdf_data::dataset::load_bundled_material;
use deepbrdf_data::rgl::{export, tabulate, ExportResolution, RglBrdf};
use pyo3::prelude::*;
use std::path::PathBuf;

/// read_merl(path) -> numpy.ndarray
///
/// Reads a MERL `.binary` file (Matusik et al. 2003): a float32 array of shape
/// (3, 90, 90, 180) (colour channel, theta_h, theta_d, phi_d) of BRDF values in 1/sr, the
/// file's stored values times MERL's colour scales; invalid (below-horizon) cells are NaN.
/// Raises an OSError subclass naming the file (FileNotFoundError, ..., FileFormatError for a
/// truncated or malformed file).
#[pyfunction]
pub fn read_merl(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let table = py.detach(|| deepbrdf_data::merl::read_merl(&path)).map_err(py_err)?;
    table_out(py, table)
}

/// write_merl(path, table) -> None
///
/// Writes a table (shape (3, 90, 90, 180), 1/sr, NaN or negative for invalid cells) as a MERL
/// `.binary` file, atomically (a temporary file renamed into place), byte for byte as
/// `experiments` writes it. Raises ValueError for a bad array, OSError for the file.
#[pyfunction]
pub fn write_merl(py: Python<'_>, path: PathBuf, table: &Bound<'_, PyAny>) -> PyResult<()> {
    let table = table_in(table, "table")?;
    py.detach(|| deepbrdf_data::merl::write_merl(&table, &path)).map_err(py_err)
}

/// read_bsdf(path) -> numpy.ndarray
///
/// Reads an RGL `.bsdf` measurement (Dupuy and Jakob 2018; isotropic) and tabulates it on the
/// MERL grid at the bin centres, as `experiments convert` does: a table like `read_merl`'s.
#[pyfunction]
pub fn read_bsdf(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyAny>> {
    let table =
        py.detach(|| RglBrdf::read(&path).and_then(|brdf| tabulate(&brdf))).map_err(py_err)?;
    table_out(py, table)
}

/// write_bsdf(path, table, *, description="table", theta_i=None, ndf=None, vndf=None,
/// rgb=None) -> None
///
/// Writes a table (shape (3, 90, 90, 180), 1/sr) as an isotropic RGB tensor file of the RGL
/// format (Dupuy and Jakob 2018), which Mitsuba 3's and pbrt-v4's `measured` materials read,
/// atomically, byte for byte as `experiments export-bsdf` writes it for the same description
/// (the CLI names it after the material) and resolutions (its defaults when None). ValueError
/// for a table or resolution the exporter refuses, OSError for the file.
#[pyfunction]
#[pyo3(signature = (path, table, *, description="table", theta_i=None, ndf=None, vndf=None, rgb=None))]
pub fn write_bsdf(
    py: Python<'_>,
    path: PathBuf,
    table: &Bound<'_, PyAny>,
    description: &str,
    theta_i: Option<usize>,
    ndf: Option<usize>,
    vndf: Option<usize>,
    rgb: Option<usize>,
) -> PyResult<()> {
    let table = table_in(table, "table")?;
    let default = ExportResolution::default();
    let resolution = ExportResolution {
        theta_i: theta_i.unwrap_or(default.theta_i),
        ndf: ndf.unwrap_or(default.ndf),
        vndf: vndf.unwrap_or(default.vndf),
        rgb: rgb.unwrap_or(default.rgb),
    };
    py.detach(|| export(&table, description, &resolution, &path).and_then(|f| f.write(&path)))
        .map_err(py_err)
}

/// bundled(name) -> numpy.ndarray
///
/// A bundled material by name (`chrome`, `merl/chrome`, `rgl/cardboard_rgb`,
/// `rgl-measured/paper_white_rgb`), tabulated on first use and cached (`$DEEPBRDF_CACHE`,
/// else `~/.cache/deepbrdf`), as the command line loads it. The `merl`, `nielsen2015` and `rgl`
/// collections are Neural-BRDF fits (Sztrajman et al. 2021) tabulated on the MERL grid, not the
/// measurements; `rgl-measured` holds seven real RGL measurements. ValueError for an unknown
/// name (the message lists close matches).
#[pyfunction]
pub fn bundled<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let (_, table) =
        py.detach(|| load_bundled_material(name, &Cache::default_location())).map_err(py_err)?;
    table_out(py, table)
}

/// bundled_names(collection=None) -> list[str]
///
/// The bundled materials as `collection/name`, sorted: of one collection (`merl`,
/// `nielsen2015`, `rgl`, `rgl-measured`) or of all four.
#[pyfunction]
#[pyo3(signature = (collection=None))]
pub fn bundled_names(collection: Option<&str>) -> PyResult<Vec<String>> {
    let collections = match collection {
        Some(name) => vec![name.parse::<Collection>().map_err(py_err)?],
        None => Collection::ALL.into_iter().chain([Collection::RglMeasured]).collect(),
    };
    let mut names = Vec::new();
    for c in collections {
        let inside = c.names().map_err(|e| value_error(e.to_string()))?;
        names.extend(inside.into_iter().map(|n| format!("{c}/{n}")));
    }
    Ok(names)
}
