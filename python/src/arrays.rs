//! numpy arrays in and out: a MERL table is a float32 array of shape (3, 90, 90, 180) (colour
//! channel, theta_h, theta_d, phi_d: MERL's file order) of BRDF values in 1/sr with invalid
//! (below-horizon) cells as NaN; a stack of tables adds a leading axis; a latent vector is a
//! float32 array of shape (k,); an image is float32 (H, W, 3) linear radiance, or (H, W, 4) with
//! the coverage as the fourth channel.
//!
//! Arrays pass through Python's buffer protocol (PyO3's safe `PyBuffer`): one copy each way,
//! between numpy's memory and the library's table; invalid values are turned into NaN (or back)
//! in the library's buffer, in parallel, with the GIL released.
use crate::errors::value_error;
use deepbrdf_data::merl::{INVALID_VALUE, N_PHI_D, N_THETA_D, N_THETA_H, VALUES};
use deepbrdf_data::MerlTable;
use deepbrdf_render::Image;
use pyo3::buffer::PyBuffer;
use pyo3::prelude::*;
use pyo3::types::PyDict;
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

/// Invalid (negative) values of a table as NaN, in place, in parallel.
fn nan_invalid(values: &mut [f32]) {
    values.par_chunks_mut(CHUNK).for_each(|chunk| {
        for v in chunk {
            if *v < 0.0 {
                *v = f32::NAN;
            }
        }
    });
}

/// A new float32 numpy array of `shape` (`numpy.empty`) holding `values`, copied once through
/// the buffer protocol.
pub fn floats_out<'py>(
    py: Python<'py>,
    values: &[f32],
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let array = py.import("numpy")?.call_method1("empty", (shape.to_vec(), "float32"))?;
    PyBuffer::<f32>::get(&array)?.copy_from_slice(py, values)?;
    Ok(array)
}

/// The numpy array of one table, invalid cells NaN.
pub fn table_out(py: Python<'_>, table: MerlTable) -> PyResult<Bound<'_, PyAny>> {
    let mut values = table.into_values();
    py.detach(|| nan_invalid(&mut values));
    floats_out(py, &values, &TABLE_SHAPE)
}

/// The numpy array (n, 3, 90, 90, 180) of a stack of tables, invalid cells NaN.
pub fn stack_out(py: Python<'_>, tables: Vec<MerlTable>) -> PyResult<Bound<'_, PyAny>> {
    let t = TABLE_SHAPE;
    let shape = vec![tables.len(), t[0], t[1], t[2], t[3]];
    let array = py.import("numpy")?.call_method1("empty", (shape, "float32"))?;
    for (i, table) in tables.into_iter().enumerate() {
        let mut values = table.into_values();
        py.detach(|| nan_invalid(&mut values));
        PyBuffer::<f32>::get(&array.get_item(i)?)?.copy_from_slice(py, &values)?;
    }
    Ok(array)
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
    floats_out(py, &values, &[h, w, c])
}
