//! numpy arrays in and out: a MERL table is a float32 array of shape (3, 90, 90, 180) (colour
//! channel, theta_h, theta_d, phi_d: MERL's file order) of BRDF values in 1/sr with invalid
//! (below-horizon) cells as NaN; a stack of tables adds a leading axis; a latent vector is a
//! float32 array of shape (k,); an image is float32 (H, W, 3) linear radiance, or (H, W, 4) with
//! the coverage as the fourth channel.
//!
//! Arrays pass through Python's buffer protocol (PyO3's safe `PyBuffer`, and a `bytearray`
//! that `numpy.frombuffer` wraps): one copy each way, between numpy's memory and the library's
//! table, with invalid values turned into NaN (or back) on the way and the GIL released while
//! the values are copied out.
use crate::errors::value_error;
use deepbrdf_data::merl::{INVALID_VALUE, N_PHI_D, N_THETA_D, N_THETA_H, VALUES};
use deepbrdf_data::MerlTable;
use deepbrdf_render::Image;
use pyo3::buffer::PyBuffer;
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyDict};
use rayon::prelude::*;

/// The shape of one table.
pub const TABLE_SHAPE: [usize; 4] = [3, N_THETA_H, N_THETA_D, N_PHI_D];

/// Values handled per parallel task when converting tables.
const CHUNK: usize = 1 << 16;

/// `obj` as a C-contiguous float32 buffer (numpy's `ascontiguousarray`, which copies nothing
/// when it already is one).
pub fn f32_buffer(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<PyBuffer<f32>> {
    let py = obj.py();
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float32")?;
    let array = py
        .import("numpy")?
        .call_method("ascontiguousarray", (obj,), Some(&kwargs))
        .map_err(|e| value_error(format!("{what}: not an array of numbers ({e})")))?;
    PyBuffer::get(&array)
}

/// `(3, 90, 90, 180)`.
pub fn shape_text(shape: &[usize]) -> String {
    let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
    match parts.len() {
        1 => format!("({},)", parts[0]),
        _ => format!("({})", parts.join(", ")),
    }
}

/// A buffer's values.
fn values_of(py: Python<'_>, buffer: &PyBuffer<f32>) -> PyResult<Vec<f32>> {
    buffer.to_vec(py)
}

/// A table from values as Python holds them (NaN for invalid cells), checked.
pub fn table_from_values(mut values: Vec<f32>, what: &str) -> PyResult<MerlTable> {
    if let Some(i) = values.iter().position(|v| v.is_infinite()) {
        return Err(value_error(format!("{what}: value {i} is {} (not finite)", values[i])));
    }
    values.par_chunks_mut(CHUNK).for_each(|chunk| {
        for v in chunk {
            if v.is_nan() {
                *v = INVALID_VALUE;
            }
        }
    });
    MerlTable::from_values(values).map_err(|e| value_error(format!("{what}: {e}")))
}

/// One table from a numpy array of shape (3, 90, 90, 180).
pub fn table_in(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<MerlTable> {
    let buffer = f32_buffer(obj, what)?;
    if buffer.shape() != TABLE_SHAPE {
        return Err(value_error(format!(
            "{what}: a MERL table is an array of shape {}, got {}",
            shape_text(&TABLE_SHAPE),
            shape_text(buffer.shape())
        )));
    }
    table_from_values(values_of(obj.py(), &buffer)?, what)
}

/// A stack of tables, shape (n, 3, 90, 90, 180), held in Python: each is copied into a table
/// when asked for, so that a long batch can stop between tables.
pub struct TableStack {
    buffer: PyBuffer<f32>,
    what: String,
}

impl TableStack {
    /// The stack of `obj`, its shape checked.
    pub fn new(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Self> {
        let buffer = f32_buffer(obj, what)?;
        let shape = buffer.shape();
        if shape.len() != 5 || shape[1..] != TABLE_SHAPE {
            return Err(value_error(format!(
                "{what}: a stack of MERL tables is an array of shape (n, 3, 90, 90, 180), got {}",
                shape_text(shape)
            )));
        }
        Ok(Self { buffer, what: what.to_string() })
    }

    pub fn len(&self) -> usize {
        self.buffer.shape()[0]
    }

    /// Table `i` of the stack.
    pub fn table(&self, py: Python<'_>, i: usize) -> PyResult<MerlTable> {
        let what = format!("{}[{i}]", self.what);
        let cells = self.buffer.as_slice(py).ok_or_else(|| value_error("not contiguous"))?;
        let values = cells[i * VALUES..(i + 1) * VALUES].iter().map(|c| c.get()).collect();
        table_from_values(values, &what)
    }
}

/// A float32 numpy array of `shape` holding `values` (library values; with `nan_invalid`,
/// negative ones, the invalid cells of tables, become NaN), copied once into a `bytearray`
/// that numpy wraps (writable, no further copy), the GIL released while copying.
pub fn array_out<'py>(
    py: Python<'py>,
    values: &[f32],
    shape: &[usize],
    nan_invalid: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let bytes = PyByteArray::new_with(py, values.len() * 4, |out| {
        py.detach(|| fill(out, values, nan_invalid));
        Ok(())
    })?;
    wrap(py, bytes, shape)
}

/// Writes `values` into `out` as native float32 bytes, in parallel (negative values as NaN
/// with `nan_invalid`).
fn fill(out: &mut [u8], values: &[f32], nan_invalid: bool) {
    out.par_chunks_mut(4 * CHUNK).zip(values.par_chunks(CHUNK)).for_each(|(o, v)| {
        for (o, &v) in o.chunks_exact_mut(4).zip(v) {
            let v = if nan_invalid && v < 0.0 { f32::NAN } else { v };
            o.copy_from_slice(&v.to_ne_bytes());
        }
    });
}

/// numpy's float32 view of `bytes`, reshaped (no copy).
fn wrap<'py>(
    py: Python<'py>,
    bytes: Bound<'py, PyByteArray>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float32")?;
    let flat = py.import("numpy")?.call_method("frombuffer", (bytes,), Some(&kwargs))?;
    flat.call_method1("reshape", (shape.to_vec(),))
}

/// The numpy array of one table.
pub fn table_out<'py>(py: Python<'py>, table: &MerlTable) -> PyResult<Bound<'py, PyAny>> {
    array_out(py, table.values(), &TABLE_SHAPE, true)
}

/// The numpy array (n, 3, 90, 90, 180) of a stack of tables, copied once.
pub fn stack_out<'py>(py: Python<'py>, tables: &[MerlTable]) -> PyResult<Bound<'py, PyAny>> {
    let t = TABLE_SHAPE;
    let bytes = PyByteArray::new_with(py, tables.len() * VALUES * 4, |out| {
        py.detach(|| {
            for (o, table) in out.chunks_exact_mut(VALUES * 4).zip(tables) {
                fill(o, table.values(), true);
            }
        });
        Ok(())
    })?;
    wrap(py, bytes, &[tables.len(), t[0], t[1], t[2], t[3]])
}

/// A latent vector, shape (k,).
pub fn latent_in(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f32>> {
    let buffer = f32_buffer(obj, what)?;
    if buffer.dimensions() != 1 {
        return Err(value_error(format!(
            "{what}: a latent vector is an array of shape (k,), got {}",
            shape_text(buffer.shape())
        )));
    }
    values_of(obj.py(), &buffer)
}

/// A stack of latent vectors, shape (n, k): the rows.
pub fn latents_in(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Vec<f32>>> {
    let buffer = f32_buffer(obj, what)?;
    let shape = buffer.shape().to_vec();
    if shape.len() != 2 || shape[1] == 0 {
        return Err(value_error(format!(
            "{what}: a stack of latent vectors is an array of shape (n, k), got {}",
            shape_text(&shape)
        )));
    }
    Ok(values_of(obj.py(), &buffer)?.chunks(shape[1]).map(<[f32]>::to_vec).collect())
}

/// An image, shape (H, W, 3) (full coverage) or (H, W, 4) (the fourth channel the coverage).
pub fn image_in(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Image> {
    let buffer = f32_buffer(obj, what)?;
    let shape = buffer.shape().to_vec();
    if shape.len() != 3 || !(shape[2] == 3 || shape[2] == 4) || shape[0] == 0 || shape[1] == 0 {
        return Err(value_error(format!(
            "{what}: an image is an array of shape (H, W, 3) or (H, W, 4), got {}",
            shape_text(&shape)
        )));
    }
    let (h, w, c) = (shape[0], shape[1], shape[2]);
    let (Ok(h32), Ok(w32)) = (u32::try_from(h), u32::try_from(w)) else {
        return Err(value_error(format!("{what}: {w}x{h} pixels is too large")));
    };
    let values = values_of(obj.py(), &buffer)?;
    let rgb = values.chunks_exact(c).map(|p| [p[0], p[1], p[2]]).collect();
    let coverage = match c {
        4 => values.chunks_exact(4).map(|p| p[3]).collect(),
        _ => vec![1.0; h * w],
    };
    Image::from_pixels(w32, h32, rgb, coverage).map_err(|e| value_error(format!("{what}: {e}")))
}

/// An image as an (H, W, 3) array, or (H, W, 4) with the coverage when `alpha`.
pub fn image_out<'py>(py: Python<'py>, image: &Image, alpha: bool) -> PyResult<Bound<'py, PyAny>> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let c = if alpha { 4 } else { 3 };
    let mut values = Vec::with_capacity(w * h * c);
    for (p, &a) in image.pixels().iter().zip(image.coverage()) {
        values.extend_from_slice(p);
        if alpha {
            values.push(a);
        }
    }
    array_out(py, &values, &[h, w, c], false)
}
