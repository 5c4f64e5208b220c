//! The spectral basis as the codec uses it (not in the paper): restricted to its support (the
//! layout values where some direction or the offset is non-zero: the MERL grid's valid cells,
//! 76% of the layout) and stored in half precision, direction by direction scaled by a power of
//! two so its largest value is near f16's top. `x_hat = mu + U^T c` and `c = U (x - mu)` then
//! read 0.67 GB instead of the 1.7 GB of the f32 basis: decoding is bound by memory bandwidth.
//!
//! Rounding a value to f16 changes it by at most 2^-11 of itself (power-of-two scales are exact,
//! and the scaling keeps values of a direction within f16's normal range down to 2^-29 of its
//! largest one), so the expansion of coordinates `c` differs from the f32 one by at most
//! `2^-11 sum_j |c_j U_j|` at each value.

use half::f16;
use half::slice::HalfFloatSliceExt;
use rayon::prelude::*;

use crate::autoencoder::{Autoencoder, INPUT_VALUES};
use crate::error::{ModelError, Result};

/// Values (support cells) per parallel chunk; a fixed size, so sums run in a fixed order.
const CHUNK: usize = 1 << 14;

/// First bytes of a serialised compact basis ([`CompactBasis::to_bytes`]).
const MAGIC: &[u8; 8] = b"DBRDFCB\0";
/// Version of that serialisation.
const FORMAT_VERSION: u32 = 1;
/// Bytes of its header: magic, version, K, support length.
const HEADER: usize = 8 + 3 * 4;

/// Support values per tile of the transposition in [`CompactBasis::new`].
const TILE: usize = 512;

/// Largest stored magnitude after scaling: 2^15, within f16's maximum (65504).
const TOP: f32 = 32768.0;

/// A basis of K directions over the §3.2 layout, on its support, in f16.
#[derive(Clone, Debug, PartialEq)]
pub struct CompactBasis {
    size: usize,
    /// Layout indices of the support, ascending.
    support: Vec<u32>,
    /// The offset mu on the support.
    offset: Vec<f32>,
    /// Value-major: `support.len()` groups of K scaled directions' values.
    values: Vec<f16>,
    /// Per direction, `1 / scale`: the stored value times this is the basis value.
    unscale: Vec<f32>,
}

impl CompactBasis {
    /// Moves the spectral basis out of `model` ([`crate::spectral::SpectralPath::take_basis`])
    /// as a compact basis around the model's offset; the network can then no longer encode or
    /// decode by itself, only run its coordinate-space MLPs.
    pub(crate) fn take_from(model: &mut Autoencoder) -> Result<Self> {
        let offset = model
            .offset()
            .ok_or_else(|| ModelError::Invalid("a network without an offset".into()))?;
        let path = model
            .spectral_mut()
            .ok_or_else(|| ModelError::Invalid("this network has no spectral path".into()))?;
        let size = path.size();
        let rows = path.take_basis()?;
        Self::new(&rows, size, &offset)
    }

    /// From `size` rows of [`INPUT_VALUES`] values (row-major, as
    /// [`crate::principal::fit_basis`] gives them) and the offset they are centred on.
    pub fn new(rows: &[f32], size: usize, offset: &[f32]) -> Result<Self> {
        if size == 0 || rows.len() != size * INPUT_VALUES || offset.len() != INPUT_VALUES {
            return Err(ModelError::Invalid(format!(
                "a basis of {size} directions needs {} values and an offset of {INPUT_VALUES}, \
                 got {} and {}",
                size * INPUT_VALUES,
                rows.len(),
                offset.len()
            )));
        }
        if let Some(i) = rows.iter().chain(offset).position(|v| !v.is_finite()) {
            return Err(ModelError::Invalid(format!("basis or offset value {i} is not finite")));
        }
        let row = |j: usize| &rows[j * INPUT_VALUES..(j + 1) * INPUT_VALUES];
        // Row by row (sequential reads), in parallel over stretches of the layout.
        let mut used: Vec<bool> = offset.iter().map(|&mu| mu != 0.0).collect();
        used.par_chunks_mut(CHUNK).enumerate().for_each(|(b, used)| {
            for j in 0..size {
                let row = &row(j)[b * CHUNK..b * CHUNK + used.len()];
                for (u, &x) in used.iter_mut().zip(row) {
                    *u |= x != 0.0;
                }
            }
        });
        let support: Vec<u32> = (0..INPUT_VALUES).filter(|&v| used[v]).map(|v| v as u32).collect();
        let mut scale = Vec::with_capacity(size);
        let mut unscale = Vec::with_capacity(size);
        for j in 0..size {
            let largest = row(j).iter().fold(0f32, |m, v| m.max(v.abs()));
            // 2^e with largest * 2^e in (TOP / 2, TOP]; 1 for an empty direction.
            let e = if largest > 0.0 { (TOP / largest).log2().floor() as i32 } else { 0 };
            scale.push(2f32.powi(e));
            unscale.push(2f32.powi(-e));
        }
        // Transposed in tiles of TILE support values, so each row is read in short sequential
        // runs and the tile being written stays in cache.
        let mut values = vec![f16::ZERO; support.len() * size];
        values.par_chunks_mut(TILE * size).zip(support.par_chunks(TILE)).for_each(|(out, tile)| {
            for (j, &s) in scale.iter().enumerate() {
                let row = row(j);
                for (c, &v) in tile.iter().enumerate() {
                    out[c * size + j] = f16::from_f32(row[v as usize] * s);
                }
            }
        });
        let offset = support.iter().map(|&v| offset[v as usize]).collect();
        Ok(Self { size, support, offset, values, unscale })
    }

    /// K, the number of directions.
    pub fn size(&self) -> usize {
        self.size
    }

    /// How many layout values the support holds.
    pub fn support_len(&self) -> usize {
        self.support.len()
    }

    /// The basis as bytes (little-endian): `DBRDFCB\0`, version (u32), K (u32), support length
    /// n (u32), the support (n u32), the offset on it (n f32), K unscale factors (f32), the
    /// values (n K f16).
    pub fn to_bytes(&self) -> Vec<u8> {
        let n = self.support.len();
        let mut out = Vec::with_capacity(HEADER + 8 * n + 4 * self.size + 2 * self.values.len());
        out.extend_from_slice(MAGIC);
        for v in [FORMAT_VERSION, self.size as u32, n as u32] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        self.support.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        self.offset.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        self.unscale.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        self.values.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        out
    }

    /// Reads [`to_bytes`](Self::to_bytes)' format, checking every size against the byte count
    /// before allocating and every value for sense; the error says what is wrong.
    pub fn from_bytes(bytes: &[u8]) -> std::result::Result<Self, String> {
        if bytes.len() < HEADER || &bytes[..8] != MAGIC {
            return Err("not a DeepBRDF compact basis (bad magic or too short)".into());
        }
        let word = |i: usize| u32::from_le_bytes(bytes[8 + 4 * i..12 + 4 * i].try_into().unwrap());
        let (version, size, n) = (word(0), word(1) as usize, word(2) as usize);
        if version != FORMAT_VERSION {
            return Err(format!("compact basis version {version}, expected {FORMAT_VERSION}"));
        }
        if size == 0 || size > 4096 || n > INPUT_VALUES {
            return Err(format!("{size} directions over {n} values is out of range"));
        }
        let expected = HEADER + 8 * n + 4 * size + 2 * n * size;
        if bytes.len() != expected {
            return Err(format!(
                "{} bytes, but K = {size} over {n} values needs {expected}",
                bytes.len()
            ));
        }
        let mut at = HEADER;
        let mut take = |len: usize| {
            let part = &bytes[at..at + len];
            at += len;
            part
        };
        let words = |b: &[u8]| -> Vec<[u8; 4]> {
            b.chunks_exact(4).map(|c| c.try_into().unwrap()).collect()
        };
        let support: Vec<u32> = words(take(4 * n)).into_iter().map(u32::from_le_bytes).collect();
        let offset: Vec<f32> = words(take(4 * n)).into_iter().map(f32::from_le_bytes).collect();
        let unscale: Vec<f32> = words(take(4 * size)).into_iter().map(f32::from_le_bytes).collect();
        let values: Vec<f16> =
            take(2 * n * size).chunks_exact(2).map(|c| f16::from_le_bytes([c[0], c[1]])).collect();
        if support.windows(2).any(|w| w[0] >= w[1])
            || support.last().is_some_and(|&v| v as usize >= INPUT_VALUES)
        {
            return Err("the support is not increasing within the layout".into());
        }
        if offset.iter().any(|v| !v.is_finite()) {
            return Err("an offset value is not finite".into());
        }
        if unscale.iter().any(|v| !v.is_finite() || *v <= 0.0) {
            return Err("a direction's scale is not a positive finite number".into());
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err("a basis value is not finite".into());
        }
        Ok(Self { size, support, offset, values, unscale })
    }

    /// `c = U ((x - mu) * mask)`: the K coordinates of a mapped layout `input` with validity
    /// `mask` (both [`INPUT_VALUES`] long). Summed in f64 chunk by chunk, in a fixed order.
    pub fn coefficients(&self, input: &[f32], mask: &[f32]) -> Result<Vec<f32>> {
        if input.len() != INPUT_VALUES || mask.len() != INPUT_VALUES {
            return Err(ModelError::Invalid(format!(
                "projecting needs {INPUT_VALUES} layout values and mask entries"
            )));
        }
        let k = self.size;
        let parts: Vec<Vec<f64>> = self
            .values
            .par_chunks(CHUNK * k)
            .zip(self.support.par_chunks(CHUNK))
            .zip(self.offset.par_chunks(CHUNK))
            .map(|((values, support), offset)| {
                let mut sum = vec![0f32; k];
                let mut row = vec![0f32; k];
                for ((group, &v), &mu) in values.chunks_exact(k).zip(support).zip(offset) {
                    let v = v as usize;
                    let centred = (input[v] - mu) * mask[v];
                    if centred != 0.0 {
                        group.convert_to_f32_slice(&mut row);
                        for (s, u) in sum.iter_mut().zip(&row) {
                            *s += u * centred;
                        }
                    }
                }
                sum.into_iter().map(f64::from).collect()
            })
            .collect();
        let mut total = vec![0f64; k];
        for part in parts {
            for (t, p) in total.iter_mut().zip(part) {
                *t += p;
            }
        }
        Ok(total.iter().zip(&self.unscale).map(|(&t, &u)| (t * f64::from(u)) as f32).collect())
    }

    /// `x_hat = mu + U^T c`: the [`INPUT_VALUES`] layout values of coordinates `c` (zero off
    /// the support).
    pub fn expand(&self, coefficients: &[f32]) -> Result<Vec<f32>> {
        if coefficients.len() != self.size {
            return Err(ModelError::Invalid(format!(
                "a basis of {} directions expands {} coordinates, got {}",
                self.size,
                self.size,
                coefficients.len()
            )));
        }
        let k = self.size;
        let c: Vec<f32> = coefficients.iter().zip(&self.unscale).map(|(c, u)| c * u).collect();
        // Stretches of the layout in parallel, each with the support values that fall in it.
        let mut full = vec![0f32; INPUT_VALUES];
        full.par_chunks_mut(CHUNK).enumerate().for_each(|(b, out)| {
            let start = b * CHUNK;
            let lo = self.support.partition_point(|&v| (v as usize) < start);
            let hi = self.support.partition_point(|&v| (v as usize) < start + out.len());
            let mut row = vec![0f32; k];
            for i in lo..hi {
                self.values[i * k..(i + 1) * k].convert_to_f32_slice(&mut row);
                out[self.support[i] as usize - start] = self.offset[i] + dot(&row, &c);
            }
        });
        Ok(full)
    }
}

/// A dot product in eight independent lanes (vectorised by the compiler).
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut lanes = [0f32; 8];
    let (a8, b8) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f32 = a8.remainder().iter().zip(b8.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in a8.zip(b8) {
        for i in 0..8 {
            lanes[i] += x[i] * y[i];
        }
    }
    lanes.iter().sum::<f32>() + tail
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two directions on disjoint stripes (one with a large dynamic range), an offset on a
    /// third stripe; the rest of the layout empty.
    fn basis() -> (Vec<f32>, Vec<f32>) {
        let mut rows = vec![0f32; 2 * INPUT_VALUES];
        for v in (0..INPUT_VALUES).step_by(3) {
            rows[v] = 1e-3 * (1.0 + (v % 17) as f32);
            rows[INPUT_VALUES + v + 1] = if v % 1000 == 0 { 5.0 } else { 1e-6 * (v % 5) as f32 };
        }
        let mut offset = vec![0f32; INPUT_VALUES];
        for v in (2..INPUT_VALUES).step_by(3) {
            offset[v] = 0.25 + (v % 7) as f32;
        }
        (rows, offset)
    }

    #[test]
    fn expansion_and_projection_match_f32_within_half_precision() {
        let (rows, offset) = basis();
        let compact = CompactBasis::new(&rows, 2, &offset).unwrap();
        // Zeros of the second direction (v % 5 == 0 off the spikes) are off the support.
        assert!(compact.support_len() < INPUT_VALUES);
        let c = [0.7f32, -3.0];
        let x = compact.expand(&c).unwrap();
        for v in 0..INPUT_VALUES {
            let exact = offset[v] + c[0] * rows[v] + c[1] * rows[INPUT_VALUES + v];
            let bound = 2f32.powi(-11)
                * (c[0] * rows[v]).abs().max((c[1] * rows[INPUT_VALUES + v]).abs())
                + 1e-6 * exact.abs();
            assert!((x[v] - exact).abs() <= bound, "value {v}: {} vs {exact}", x[v]);
        }
        // Projection: of x itself (masked everywhere valid) the coordinates come back.
        let ones = vec![1f32; INPUT_VALUES];
        let norms: Vec<f64> = (0..2)
            .map(|j| {
                rows[j * INPUT_VALUES..(j + 1) * INPUT_VALUES]
                    .iter()
                    .map(|&u| f64::from(u) * f64::from(u))
                    .sum()
            })
            .collect();
        let got = compact.coefficients(&x, &ones).unwrap();
        for j in 0..2 {
            let expected = f64::from(c[j]) * norms[j];
            assert!((f64::from(got[j]) - expected).abs() < 2e-3 * expected.abs(), "{j}: {got:?}");
        }
        // A zero mask gives zero coordinates.
        assert_eq!(compact.coefficients(&x, &vec![0f32; INPUT_VALUES]).unwrap(), vec![0.0; 2]);
    }

    #[test]
    fn bytes_round_trip_and_damage_is_named() {
        let (rows, offset) = basis();
        let compact = CompactBasis::new(&rows, 2, &offset).unwrap();
        let bytes = compact.to_bytes();
        let back = CompactBasis::from_bytes(&bytes).unwrap();
        assert_eq!(back.expand(&[0.3, 0.4]).unwrap(), compact.expand(&[0.3, 0.4]).unwrap());
        let err = |b: &[u8]| CompactBasis::from_bytes(b).unwrap_err();
        assert!(err(&bytes[..bytes.len() - 1]).contains("bytes"));
        assert!(err(&bytes[..10]).contains("magic"));
        let mut absurd = bytes.clone();
        absurd[16..20].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(err(&absurd).contains("out of range"));
        let mut unsorted = bytes.clone();
        unsorted[HEADER..HEADER + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(err(&unsorted).contains("support"));
        let mut nan = bytes.clone();
        let last = nan.len() - 2;
        nan[last..].copy_from_slice(&f16::NAN.to_le_bytes());
        assert!(err(&nan).contains("not finite"));
    }

    #[test]
    fn bad_shapes_and_values_are_rejected() {
        let (rows, offset) = basis();
        assert!(CompactBasis::new(&rows[1..], 2, &offset).is_err());
        assert!(CompactBasis::new(&rows, 2, &offset[1..]).is_err());
        let mut nan = offset.clone();
        nan[5] = f32::NAN;
        assert!(CompactBasis::new(&rows, 2, &nan).is_err());
        let compact = CompactBasis::new(&rows, 2, &offset).unwrap();
        assert!(compact.expand(&[1.0]).is_err());
        assert!(compact.coefficients(&offset[1..], &offset).is_err());
    }
}
