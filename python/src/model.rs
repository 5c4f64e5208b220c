//! `deepbrdf.Model`: a trained DeepBRDF model from Python (Hu et al. 2020): encode (eq. 2),
//! decode (eq. 3), edit through the attributes' regressor (§5.1, eq. 7), interpolate latents
//! (Fig. 10), recover a material from one photo (§5.2), each the library call `experiments`
//! makes. Every call releases the GIL while it computes; the batch forms and interpolation
//! check for Ctrl-C between tables.
use crate::arrays::{
    floats_out, image_in, latent_in, latents_in, stack_out, table_in, table_out, TableStack,
};
use crate::errors::{py_err, value_error};
use deepbrdf_data::MerlTable;
use deepbrdf_eval::attributes::{fit, FitConfig};
use deepbrdf_eval::editing::{
    blend, edit_material, path_weights, ColourEdit, Edit, EditMode, ScalarEdit, DEFAULT_MODE,
};
use deepbrdf_model::burn::tensor::Device;
use deepbrdf_model::recovery::artifact::RECOVERY_DIR;
use deepbrdf_model::recovery::RecoveryArtifact;
use deepbrdf_model::refine::Refinement;
use deepbrdf_model::regressor::TargetKind;
use deepbrdf_model::shipped::REGRESSOR_DIR;
use deepbrdf_model::{DeepBrdf, DeviceKind, Regressor, DEFAULT_MODEL_DIR};
use deepbrdf_render::image::Srgb8Image;
use deepbrdf_render::Photo;
use pyo3::buffer::PyBuffer;
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::OnceLock;
use std::time::Instant;

/// Model.load(path=None, *, refine=None, device=None)
///
/// A trained DeepBRDF model: `Model.load()` is the shipped model (`models/default` of the
/// checkout the package was built from), `Model.load(path)` a model directory (or a training
/// directory holding `model/`) as `experiments --model DIR` takes it. Tables are float32
/// arrays (3, 90, 90, 180) in 1/sr with NaN for invalid cells; latents float32 arrays (k,).
#[pyclass(module = "deepbrdf", frozen)]
pub struct Model {
    model: DeepBrdf,
    dir: PathBuf,
    device: Device,
    regressor: OnceLock<Regressor>,
    recovery: OnceLock<RecoveryArtifact>,
}

impl Model {
    /// The regressor of eq. (7), loaded on first use.
    fn regressor(&self) -> PyResult<&Regressor> {
        if self.regressor.get().is_none() {
            let dir = self.dir.join(REGRESSOR_DIR);
            let r = Regressor::load_for(
                &dir,
                TargetKind::DeepBrdf,
                self.model.id(),
                self.model.k(),
                &self.device,
            )
            .map_err(py_err)?;
            let _ = self.regressor.set(r);
        }
        self.regressor.get().ok_or_else(|| value_error("the regressor did not load"))
    }

    /// The recovery network of §5.2, loaded on first use and checked to predict this model's
    /// latent.
    fn recovery(&self) -> PyResult<&RecoveryArtifact> {
        if self.recovery.get().is_none() {
            let network = RecoveryArtifact::load(&self.dir.join(RECOVERY_DIR)).map_err(py_err)?;
            network.check_model(self.model.id()).map_err(py_err)?;
            let _ = self.recovery.set(network);
        }
        self.recovery.get().ok_or_else(|| value_error("the recovery network did not load"))
    }

    /// Decodes `latent` (the GIL released).
    fn decode_table(&self, py: Python<'_>, latent: &[f32]) -> PyResult<MerlTable> {
        py.detach(|| self.model.decode(latent)).map_err(py_err)
    }

    /// The photo of `image`: a path (PNG, JPEG, EXR), a uint8 array (H, W, 3) of sRGB values or
    /// a float array (H, W, 3|4) of linear radiance (with coverage).
    fn photo(&self, py: Python<'_>, image: &Bound<'_, PyAny>) -> PyResult<(Photo, String)> {
        if let Ok(path) = image.extract::<PathBuf>() {
            let photo = py.detach(|| Photo::read(&path)).map_err(py_err)?;
            return Ok((photo, path.display().to_string()));
        }
        if let Ok(bytes) = PyBuffer::<u8>::get(image) {
            let shape = bytes.shape().to_vec();
            if shape.len() != 3 || shape[2] != 3 {
                return Err(value_error(format!(
                    "image: a uint8 photo is an array of shape (H, W, 3), got {shape:?}"
                )));
            }
            let (Ok(height), Ok(width)) = (u32::try_from(shape[0]), u32::try_from(shape[1])) else {
                return Err(value_error("image: too large"));
            };
            let data = bytes.to_vec(py)?;
            return Ok((Photo::from_srgb8(&Srgb8Image { width, height, data }), "image".into()));
        }
        Ok((Photo::from_linear(&image_in(image, "image")?), "image".into()))
    }
}

#[pymethods]
impl Model {
    /// Model.load(path=None, *, refine=None, device=None) -> Model
    ///
    /// Loads a model: the shipped one when `path` is None. `refine` is the number of
    /// Levenberg-Marquardt steps refining each encoding through the decoder (the command
    /// line's `--refine`, same default; 0: the encoder's latent). `device` names a compiled-in
    /// backend (`flex`, the default, or `ndarray`).
    #[staticmethod]
    #[pyo3(signature = (path=None, *, refine=None, device=None))]
    fn load(
        py: Python<'_>,
        path: Option<PathBuf>,
        refine: Option<usize>,
        device: Option<&str>,
    ) -> PyResult<Self> {
        let dir = path.unwrap_or_else(|| PathBuf::from(DEFAULT_MODEL_DIR));
        let kind = match device {
            Some(name) => name.parse::<DeviceKind>().map_err(|e| value_error(e.to_string()))?,
            None => DeviceKind::default_kind()
                .ok_or_else(|| value_error("no compute backend is compiled in"))?,
        };
        let device = kind.device().map_err(value_error)?;
        let mut refinement = Refinement::default();
        refinement.iterations = refine.unwrap_or(refinement.iterations);
        let model = py
            .detach(|| DeepBrdf::load(&dir, &device).map(|m| m.with_refinement(refinement)))
            .map_err(py_err)?;
        Ok(Self { model, dir, device, regressor: OnceLock::new(), recovery: OnceLock::new() })
    }

    /// k, the number of latent values.
    #[getter]
    fn k(&self) -> usize {
        self.model.k()
    }

    /// The model's id (the digest a latent file of `experiments encode` records).
    #[getter]
    fn id(&self) -> String {
        self.model.id().to_string()
    }

    /// The model directory.
    #[getter]
    fn path(&self) -> PathBuf {
        self.dir.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(path={:?}, k={}, id={})",
            self.dir.display(),
            self.model.k(),
            self.model.id()
        )
    }

    /// encode(table) -> numpy.ndarray
    ///
    /// Eq. (2): the k latent values of a table, float32 (k,), as `experiments encode` computes
    /// them.
    fn encode<'py>(
        &self,
        py: Python<'py>,
        table: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let table = table_in(table, "table")?;
        let latent = py.detach(|| self.model.encode(&table)).map_err(py_err)?;
        floats_out(py, &latent, &[latent.len()])
    }

    /// encode_batch(tables) -> numpy.ndarray
    ///
    /// `encode` of each table of a stack (n, 3, 90, 90, 180): float32 (n, k).
    fn encode_batch<'py>(
        &self,
        py: Python<'py>,
        tables: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let stack = TableStack::new(tables, "tables")?;
        let mut rows = Vec::with_capacity(stack.len() * self.model.k());
        for i in 0..stack.len() {
            let table = stack.table(py, i)?;
            rows.extend(py.detach(|| self.model.encode(&table)).map_err(py_err)?);
            py.check_signals()?;
        }
        floats_out(py, &rows, &[stack.len(), self.model.k()])
    }

    /// decode(latent) -> numpy.ndarray
    ///
    /// Eq. (3): the full table of a latent vector (k,), float32 (3, 90, 90, 180), NaN where
    /// the MERL grid has no measurement; byte for byte what `experiments decode` writes.
    fn decode<'py>(
        &self,
        py: Python<'py>,
        latent: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let latent = latent_in(latent, "latent")?;
        let table = self.decode_table(py, &latent)?;
        table_out(py, table)
    }

    /// decode_batch(latents) -> numpy.ndarray
    ///
    /// `decode` of each row of (n, k): float32 (n, 3, 90, 90, 180).
    fn decode_batch<'py>(
        &self,
        py: Python<'py>,
        latents: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rows = latents_in(latents, "latents")?;
        let mut tables = Vec::with_capacity(rows.len());
        for row in &rows {
            tables.push(self.decode_table(py, row)?);
            py.check_signals()?;
        }
        stack_out(py, tables)
    }

    /// reconstruct(table) -> numpy.ndarray
    ///
    /// Encode then decode (`experiments reconstruct`).
    fn reconstruct<'py>(
        &self,
        py: Python<'py>,
        table: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let table = table_in(table, "table")?;
        let out = py.detach(|| self.model.reconstruct(&table)).map_err(py_err)?;
        table_out(py, out)
    }

    /// reconstruct_batch(tables) -> numpy.ndarray
    ///
    /// `reconstruct` of each table of a stack (n, 3, 90, 90, 180).
    fn reconstruct_batch<'py>(
        &self,
        py: Python<'py>,
        tables: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let stack = TableStack::new(tables, "tables")?;
        let mut out = Vec::with_capacity(stack.len());
        for i in 0..stack.len() {
            let table = stack.table(py, i)?;
            out.push(py.detach(|| self.model.reconstruct(&table)).map_err(py_err)?);
            py.check_signals()?;
        }
        stack_out(py, out)
    }

    /// edit(table, *, diffuse=None, diffuse_scale=None, specular=None, specular_scale=None,
    /// roughness=None, roughness_scale=None, mode="parts") -> numpy.ndarray
    ///
    /// §5.1: the table with its diffuse albedo, specular albedo or roughness set (`diffuse=(r,
    /// g, b)`, `roughness=alpha`) or scaled (`*_scale=x`), as `experiments edit` does with the
    /// same options. `mode`: `parts` (default, no network: the table split into a floor, lobes,
    /// a retro-reflective ridge and a sheen, each lobe stretched by its own roughness), `stretch`
    /// (no network: the table's own highlight stretched to the new roughness, the albedos as
    /// `analytic`), `analytic` (no network: the fitted lobe swapped), or through the model's
    /// regressor (eq. 7) and decoder: `residual` (`Y' = Y + Phi(alpha') - Phi(alpha)`), `paper`
    /// (`Y' = Phi(alpha')`), `nearest` (the latent nearest `Y` whose attributes, as a linear
    /// latent-to-attribute predictor reads them, change by `alpha' - alpha`), `transfer` (the
    /// residual edit's change carried onto the table).
    #[pyo3(signature = (table, *, diffuse=None, diffuse_scale=None, specular=None,
        specular_scale=None, roughness=None, roughness_scale=None, mode=None))]
    #[allow(clippy::too_many_arguments)]
    fn edit<'py>(
        &self,
        py: Python<'py>,
        table: &Bound<'py, PyAny>,
        diffuse: Option<[f64; 3]>,
        diffuse_scale: Option<f64>,
        specular: Option<[f64; 3]>,
        specular_scale: Option<f64>,
        roughness: Option<f64>,
        roughness_scale: Option<f64>,
        mode: Option<&str>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let edit = Edit {
            diffuse: ColourEdit::set_or_scale("diffuse", diffuse, diffuse_scale).map_err(py_err)?,
            specular: ColourEdit::set_or_scale("specular", specular, specular_scale)
                .map_err(py_err)?,
            roughness: ScalarEdit::set_or_scale("roughness", roughness, roughness_scale)
                .map_err(py_err)?,
        };
        let mode = match mode {
            Some(name) => name.parse::<EditMode>().map_err(py_err)?,
            None => DEFAULT_MODE,
        };
        let table = table_in(table, "table")?;
        let regressor = match mode.needs_network() {
            true => Some(self.regressor()?),
            false => None,
        };
        let (edited, notes) = py
            .detach(|| {
                let original = fit(&table, &FitConfig::default())?.attributes;
                let editor = regressor.map(|r| (&self.model, r));
                let notes = edit.without_effect(&original);
                edit_material(&table, &original, &edit, mode, editor).map(|e| (e, notes))
            })
            .map_err(py_err)?;
        // What the edit cannot change (an albedo the fit finds none of) is a UserWarning.
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        for note in notes {
            let message = std::ffi::CString::new(note).map_err(|e| value_error(e.to_string()))?;
            PyErr::warn(py, &category, &message, 1)?;
        }
        table_out(py, edited.table)
    }

    /// interpolate(a, b, steps=9) -> numpy.ndarray
    ///
    /// Fig. 10's DeepBRDF path: the tables decoded from `(1 - t) z_a + t z_b` for `steps`
    /// values of t from 0 to 1, float32 (steps, 3, 90, 90, 180) (`experiments interpolate`'s
    /// first row).
    #[pyo3(signature = (a, b, steps=9))]
    fn interpolate<'py>(
        &self,
        py: Python<'py>,
        a: &Bound<'py, PyAny>,
        b: &Bound<'py, PyAny>,
        steps: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        if steps < 2 {
            return Err(value_error(format!("steps {steps}: at least 2 (both ends)")));
        }
        let (ta, tb): (MerlTable, MerlTable) = (table_in(a, "a")?, table_in(b, "b")?);
        let za = py.detach(|| self.model.encode(&ta)).map_err(py_err)?;
        py.check_signals()?;
        let zb = py.detach(|| self.model.encode(&tb)).map_err(py_err)?;
        let mut tables = Vec::with_capacity(steps);
        for t in path_weights(steps) {
            py.check_signals()?;
            tables.push(self.decode_table(py, &blend(&za, &zb, t))?);
        }
        stack_out(py, tables)
    }

    /// recover(image) -> numpy.ndarray
    ///
    /// §5.2: the table of the material in one photo, through the model's recovery network and
    /// decoder (`experiments recover`). `image`: a path (PNG, JPEG or EXR), a uint8 array
    /// (H, W, 3) of sRGB values, or a float array (H, W, 3) of linear radiance ((H, W, 4): the
    /// fourth channel the object's coverage). One object of one material, roughly centred, on
    /// a plain dark background; blank, saturated or object-less photos raise ValueError.
    fn recover<'py>(
        &self,
        py: Python<'py>,
        image: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let network = self.recovery()?;
        let (photo, what) = self.photo(py, image)?;
        let side = network.config().input_side as u32;
        let table = py.detach(|| {
            let input = photo.network_input(side, &what).map_err(py_err)?;
            let mut latents =
                network.predictor(&self.device).and_then(|p| p.predict(&input)).map_err(py_err)?;
            let latent = latents.pop().ok_or_else(|| value_error("no latent predicted"))?;
            self.model.decode(&latent).map_err(py_err)
        })?;
        table_out(py, table)
    }

    /// library_decode_seconds(latent, repeats=10) -> list[float]
    ///
    /// The library's own time for each of `repeats` decodes of `latent` (no numpy array made):
    /// the reference the benchmark compares `decode` with.
    #[pyo3(signature = (latent, repeats=10))]
    fn library_decode_seconds(
        &self,
        py: Python<'_>,
        latent: &Bound<'_, PyAny>,
        repeats: usize,
    ) -> PyResult<Vec<f64>> {
        let latent = latent_in(latent, "latent")?;
        let mut seconds = Vec::with_capacity(repeats);
        for _ in 0..repeats {
            let start = Instant::now();
            let table = py.detach(|| self.model.decode(&latent)).map_err(py_err)?;
            seconds.push(start.elapsed().as_secs_f64());
            drop(table);
            py.check_signals()?;
        }
        Ok(seconds)
    }
}
