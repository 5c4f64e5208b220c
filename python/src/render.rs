//! Rendering, image files and the measures from Python: the path tracer of `deepbrdf_render`
//! (linear radiance), PNG and OpenEXR files as `experiments render` writes them, the image
//! RelAE of Fig. 7 and the 7 editable attributes of §5.1 (Hu et al. 2020).
use crate::arrays::{f32_buffer, image_in, image_out, table_in};
use crate::errors::{py_err, value_error};
use deepbrdf_data::Silent;
use deepbrdf_eval::attributes::{fit, FitConfig};
use deepbrdf_eval::metrics::{image_relae, relae as image_pair_relae, ImageRelaeConfig};
use deepbrdf_render::{MerlBrdf, Projection, RenderSettings, SceneConfig, Tonemap};
use pyo3::prelude::*;
use std::path::PathBuf;

/// render(table, *, shape="sphere", light="sun:40,30", view=(70.0, 0.0), fov=None, size=256,
/// spp=64, seed=0, sampler="sobol", alpha=False) -> numpy.ndarray
///
/// Renders a table on one shape (sphere, plane, torus, ellipsoid, cylinder) under `light`
/// (`sun:ELEV,AZIM[,TURBIDITY]` Preetham sun and sky, `dir:THETA,PHI`, `const[:L]`), seen from
/// `view` (polar angle and azimuth in degrees), orthographic or with a vertical field of view
/// `fov`, `size` x `size` pixels with `spp` samples per pixel: a float32 array (H, W, 3) of
/// linear radiance, or (H, W, 4) with the coverage as fourth channel when `alpha`. The same
/// arguments give the same pixels as `experiments render` (its `--exr`). Omitted arguments take
/// the command line's defaults.
#[pyfunction]
#[pyo3(signature = (table, *, shape=None, light=None, view=None, fov=None, size=None, spp=None,
    seed=None, sampler=None, alpha=false))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    table: &Bound<'py, PyAny>,
    shape: Option<&str>,
    light: Option<&str>,
    view: Option<(f64, f64)>,
    fov: Option<f64>,
    size: Option<u32>,
    spp: Option<u32>,
    seed: Option<u64>,
    sampler: Option<&str>,
    alpha: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let table = table_in(table, "table")?;
    let mut config = SceneConfig::default();
    if let Some(s) = shape {
        config.shape = s.parse().map_err(py_err)?;
    }
    if let Some(l) = light {
        config.light = l.parse().map_err(py_err)?;
    }
    if let Some((theta, phi)) = view {
        if !theta.is_finite() || !phi.is_finite() {
            return Err(value_error(format!("view ({theta}, {phi}): expected finite degrees")));
        }
        (config.view_theta_deg, config.view_phi_deg) = (theta, phi);
    }
    if let Some(fov_deg) = fov {
        config.projection = Projection::Perspective { fov_deg };
    }
    let mut settings = RenderSettings::default();
    settings.size = size.unwrap_or(settings.size);
    settings.spp = spp.unwrap_or(settings.spp);
    settings.seed = seed.unwrap_or(settings.seed);
    if let Some(s) = sampler {
        settings.sampler = s.parse().map_err(py_err)?;
    }
    let image = py
        .detach(|| {
            let scene = config.build()?;
            deepbrdf_render::render(&scene, &MerlBrdf::new(&table), &settings, &Silent)
        })
        .map_err(py_err)?;
    image_out(py, &image, alpha)
}

/// The tonemapping of `exposure`, checked.
fn tonemap(exposure: f32) -> PyResult<Tonemap> {
    if !(exposure.is_finite() && exposure > 0.0) {
        return Err(value_error(format!("exposure {exposure} must be positive")));
    }
    Ok(Tonemap { exposure })
}

/// write_png(path, image, exposure=1.0) -> None
///
/// Writes a linear image (H, W, 3) or (H, W, 4) as an 8-bit sRGB PNG, tonemapped as
/// `experiments render -o` does (times `exposure`, clipped, over black), atomically.
#[pyfunction]
#[pyo3(signature = (path, image, exposure=1.0))]
pub fn write_png(
    py: Python<'_>,
    path: PathBuf,
    image: &Bound<'_, PyAny>,
    exposure: f32,
) -> PyResult<()> {
    let image = image_in(image, "image")?;
    let tonemap = tonemap(exposure)?;
    py.detach(|| image.write_png(&path, &tonemap)).map_err(py_err)
}

/// write_exr(path, image) -> None
///
/// Writes a linear image as OpenEXR (R, G, B float32 and the coverage as A: the fourth channel
/// of an (H, W, 4) image, else 1), as `experiments render --exr` does, atomically.
#[pyfunction]
pub fn write_exr(py: Python<'_>, path: PathBuf, image: &Bound<'_, PyAny>) -> PyResult<()> {
    let image = image_in(image, "image")?;
    py.detach(|| image.write_exr(&path)).map_err(py_err)
}

/// relae(a, b) -> float
///
/// The relative absolute error `sum |B - A| / sum |A|` over the object's pixels, `a` the
/// reference. Two tables: their image RelAE (Fig. 7's measure), both rendered on the preview
/// sphere under the default sun and sky (128 px, 16 spp) with `a`'s sampling, as `experiments`
/// scores reconstructions. Two images (H, W, 3|4): of those pixels (the fourth channel is the
/// coverage that says which are on the object; without it every pixel is).
#[pyfunction]
pub fn relae(py: Python<'_>, a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<f64> {
    if f32_buffer(a, "a")?.dimensions() == 4 {
        let (ta, tb) = (table_in(a, "a")?, table_in(b, "b")?);
        py.detach(|| image_relae(&ta, &tb, &ImageRelaeConfig::default())).map_err(py_err)
    } else {
        let (ia, ib) = (image_in(a, "a")?, image_in(b, "b")?);
        py.detach(|| image_pair_relae(&ib, &ia)).map_err(py_err)
    }
}

/// attributes(table) -> numpy.ndarray
///
/// The 7 editable attributes of §5.1, estimated by the library's Lambertian + GGX fit (as
/// `experiments attributes` and `edit` estimate them): float64 array
/// [diffuse R, G, B, specular R, G, B, roughness] (albedos in [0, 1], GGX alpha).
#[pyfunction]
pub fn attributes<'py>(py: Python<'py>, table: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let table = table_in(table, "table")?;
    let fitted = py.detach(|| fit(&table, &FitConfig::default())).map_err(py_err)?;
    let values = fitted.attributes.to_array().to_vec();
    py.import("numpy")?.call_method1("array", (values,))
}
