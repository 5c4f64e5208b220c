//! The RGL "tensor file" container (Dupuy & Jakob 2018, the `.bsdf` files of the RGL material
//! database), read as the authors' reference loader `powitacq` (`Tensor::Tensor` in
//! `powitacq_rgb.inl`) defines it: the 12 bytes `tensor_file\0`, version bytes 1.0, a u32 field
//! count, then per field a u16 name length, the name, a u16 rank, a u8 dtype (1-11: u8, i8, u16,
//! i16, u32, i32, u64, i64, f16, f32, f64), a u64 byte offset of the data and `rank` u64
//! dimensions; the data are little-endian and C-contiguous (last dimension fastest).
//!
//! Unlike the reference, nothing is trusted: the whole file is read once after checking its size
//! ([`MAX_FILE_BYTES`]), and every count, name, rank, dimension product and data range is checked
//! against the bytes actually present before anything is allocated, so a corrupt header can never
//! ask for a large allocation. Every error names the file and the field.

use crate::error::{DataError, Result};
use crate::files::{open_regular, read_exactly};
use std::path::{Path, PathBuf};

/// The magic bytes opening a tensor file.
pub const MAGIC: &[u8; 12] = b"tensor_file\0";
/// The only version the format has (major, minor).
pub const VERSION: [u8; 2] = [1, 0];
/// Largest tensor file read (the RGL files are 0.6-1.1 MB; anisotropic ones reach ~60 MB).
pub const MAX_FILE_BYTES: u64 = 1 << 30;
/// Bytes before the first field description: magic, version, field count.
const PREAMBLE: usize = 12 + 2 + 4;

/// The element type of a field (the format's dtype codes 1-11).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    U8,
    I8,
    U16,
    I16,
    U32,
    I32,
    U64,
    I64,
    F16,
    F32,
    F64,
}

impl Dtype {
    /// The dtype of a format code, if it is one (0 means invalid in the format).
    pub fn from_code(code: u8) -> Option<Self> {
        use Dtype::*;
        Some(match code {
            1 => U8,
            2 => I8,
            3 => U16,
            4 => I16,
            5 => U32,
            6 => I32,
            7 => U64,
            8 => I64,
            9 => F16,
            10 => F32,
            11 => F64,
            _ => return None,
        })
    }

    /// Bytes per element.
    pub fn size(self) -> usize {
        use Dtype::*;
        match self {
            U8 | I8 => 1,
            U16 | I16 | F16 => 2,
            U32 | I32 | F32 => 4,
            U64 | I64 | F64 => 8,
        }
    }

    /// The format's code of the type (the inverse of [`Dtype::from_code`]).
    pub fn code(self) -> u8 {
        use Dtype::*;
        match self {
            U8 => 1,
            I8 => 2,
            U16 => 3,
            I16 => 4,
            U32 => 5,
            I32 => 6,
            U64 => 7,
            I64 => 8,
            F16 => 9,
            F32 => 10,
            F64 => 11,
        }
    }

    /// Whether the type is a floating-point type.
    pub fn is_float(self) -> bool {
        matches!(self, Dtype::F16 | Dtype::F32 | Dtype::F64)
    }
}

/// One named n-dimensional array of a tensor file.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    name: String,
    dtype: Dtype,
    shape: Vec<usize>,
    /// The raw little-endian elements, `len() * dtype.size()` bytes.
    bytes: Vec<u8>,
}

impl Field {
    /// A field from its parts, which the caller has checked agree (`tensor_write`).
    pub(super) fn new_unchecked(
        name: String,
        dtype: Dtype,
        shape: Vec<usize>,
        bytes: Vec<u8>,
    ) -> Self {
        Self { name, dtype, shape, bytes }
    }

    /// The field's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The element type.
    pub fn dtype(&self) -> Dtype {
        self.dtype
    }

    /// The dimensions, slowest first.
    pub fn shape(&self) -> &[usize] {
        &self.shape
    }

    /// Number of elements (product of the dimensions).
    pub fn len(&self) -> usize {
        self.bytes.len() / self.dtype.size()
    }

    /// Whether the field has no elements.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// The raw little-endian bytes of the elements.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// Every element as f64 (exact for all types but 64-bit integers beyond 2^53).
    pub fn to_f64(&self) -> Vec<f64> {
        let b = &self.bytes;
        let n = self.dtype.size();
        let word = |i: usize| -> [u8; 8] {
            let mut w = [0u8; 8];
            w[..n].copy_from_slice(&b[i * n..(i + 1) * n]);
            w
        };
        (0..self.len())
            .map(|i| {
                let w = word(i);
                match self.dtype {
                    Dtype::U8 => f64::from(w[0]),
                    Dtype::I8 => f64::from(w[0] as i8),
                    Dtype::U16 => f64::from(u16::from_le_bytes([w[0], w[1]])),
                    Dtype::I16 => f64::from(i16::from_le_bytes([w[0], w[1]])),
                    Dtype::U32 => f64::from(u32::from_le_bytes([w[0], w[1], w[2], w[3]])),
                    Dtype::I32 => f64::from(i32::from_le_bytes([w[0], w[1], w[2], w[3]])),
                    Dtype::U64 => u64::from_le_bytes(w) as f64,
                    Dtype::I64 => i64::from_le_bytes(w) as f64,
                    Dtype::F16 => f64::from(half::f16::from_le_bytes([w[0], w[1]])),
                    Dtype::F32 => f64::from(f32::from_le_bytes([w[0], w[1], w[2], w[3]])),
                    Dtype::F64 => f64::from_le_bytes(w),
                }
            })
            .collect()
    }

    /// The elements of an f32 field; `None` for other types.
    pub fn to_f32(&self) -> Option<Vec<f32>> {
        (self.dtype == Dtype::F32).then(|| {
            self.bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect()
        })
    }
}

/// A parsed tensor file: its fields in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct TensorFile {
    path: PathBuf,
    fields: Vec<Field>,
}

impl TensorFile {
    /// A tensor file from fields the caller has checked (`tensor_write`).
    pub(super) fn new_unchecked(path: PathBuf, fields: Vec<Field>) -> Self {
        Self { path, fields }
    }

    /// Reads and parses the tensor file at `path`.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let (mut file, len) = open_regular(path)?;
        if len > MAX_FILE_BYTES {
            return Err(DataError::format(
                path,
                format!(
                    "{len} bytes: larger than the {MAX_FILE_BYTES} bytes a tensor file may have"
                ),
            ));
        }
        let bytes = read_exactly(&mut file, path, len as usize)?;
        Self::parse(path, &bytes)
    }

    /// Parses the bytes of a tensor file; `path` names it in errors.
    pub fn parse(path: impl AsRef<Path>, bytes: &[u8]) -> Result<Self> {
        let path = path.as_ref();
        let err = |problem: String| DataError::format(path, problem);
        if bytes.len() < PREAMBLE {
            return Err(err(format!(
                "truncated: {} bytes, a tensor file starts with {PREAMBLE}",
                bytes.len()
            )));
        }
        if &bytes[..12] != MAGIC {
            return Err(err("not a tensor file (the magic `tensor_file` is missing)".into()));
        }
        if bytes[12..14] != VERSION {
            return Err(err(format!(
                "tensor file version {}.{}, only 1.0 is known",
                bytes[12], bytes[13]
            )));
        }
        let mut r = Reader { bytes, pos: 12 + 2 };
        let n_fields = r.u32().map_err(|_| err("truncated field count".into()))? as usize;
        // A field description takes at least 13 bytes: a bound before anything is allocated.
        if n_fields > (bytes.len() - PREAMBLE) / 13 {
            return Err(err(format!(
                "header declares {n_fields} fields, more than {} bytes can describe",
                bytes.len()
            )));
        }
        let mut fields: Vec<Field> = Vec::with_capacity(n_fields);
        for index in 0..n_fields {
            let field = r.field(index).map_err(err)?;
            if fields.iter().any(|f| f.name == field.name) {
                return Err(err(format!("field {:?} appears twice", field.name)));
            }
            fields.push(field);
        }
        Ok(Self { path: path.to_path_buf(), fields })
    }

    /// The file this was read from (as given).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The fields, in file order.
    pub fn fields(&self) -> &[Field] {
        &self.fields
    }

    /// The field called `name`, if any.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// The field called `name`, or an error naming the file and the field.
    pub fn require(&self, name: &str) -> Result<&Field> {
        self.field(name).ok_or_else(|| DataError::format(&self.path, format!("no field {name:?}")))
    }

    /// The elements of the f32 field `name` after checking its rank and that every element is
    /// finite; errors name the file and the field.
    pub fn f32_field(&self, name: &str, rank: usize) -> Result<(&[usize], Vec<f32>)> {
        let field = self.require(name)?;
        let problem = |p: String| DataError::format(&self.path, format!("field {name:?}: {p}"));
        if field.shape.len() != rank {
            return Err(problem(format!("rank {}, expected {rank}", field.shape.len())));
        }
        let values = field
            .to_f32()
            .ok_or_else(|| problem(format!("type {:?}, expected F32", field.dtype)))?;
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(problem(format!("element {i} is {} (not finite)", values[i])));
        }
        Ok((&field.shape, values))
    }
}

/// A cursor over the header bytes; every read checks that the bytes exist.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> std::result::Result<&[u8], ()> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.bytes.len()).ok_or(())?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn u16(&mut self) -> std::result::Result<u16, ()> {
        self.take(2).map(|b| u16::from_le_bytes([b[0], b[1]]))
    }

    fn u32(&mut self) -> std::result::Result<u32, ()> {
        self.take(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn u64(&mut self) -> std::result::Result<u64, ()> {
        self.take(8).map(|b| {
            let mut w = [0u8; 8];
            w.copy_from_slice(b);
            u64::from_le_bytes(w)
        })
    }

    /// Parses the description of field number `index` and copies its data.
    fn field(&mut self, index: usize) -> std::result::Result<Field, String> {
        let trunc = |what: &str| format!("field #{index}: truncated header ({what})");
        let name_len = self.u16().map_err(|()| trunc("name length"))? as usize;
        let name_bytes = self.take(name_len).map_err(|()| trunc("name"))?;
        let name = std::str::from_utf8(name_bytes)
            .map_err(|_| format!("field #{index}: name is not UTF-8"))?
            .to_owned();
        let label = format!("field #{index} {name:?}");
        let rank = self.u16().map_err(|()| trunc("rank"))? as usize;
        let code = self.take(1).map_err(|()| trunc("dtype"))?[0];
        let dtype =
            Dtype::from_code(code).ok_or_else(|| format!("{label}: unknown dtype code {code}"))?;
        let offset = self.u64().map_err(|()| trunc("offset"))?;
        if rank.saturating_mul(8) > self.bytes.len() - self.pos {
            return Err(format!("{label}: rank {rank} needs more header bytes than the file has"));
        }
        let mut shape = Vec::with_capacity(rank);
        let mut bytes_needed = dtype.size() as u64;
        for _ in 0..rank {
            let dim = self.u64().map_err(|()| trunc("dimensions"))?;
            shape.push(dim);
            bytes_needed = bytes_needed.saturating_mul(dim);
        }
        let file_len = self.bytes.len() as u64;
        let fits = offset.checked_add(bytes_needed).is_some_and(|end| end <= file_len);
        if !fits {
            return Err(format!(
                "{label}: shape {shape:?} of {dtype:?} at offset {offset} needs {bytes_needed} \
                 bytes, beyond the end of the {file_len}-byte file"
            ));
        }
        // Every dimension is now bounded by the file size, so these conversions are exact.
        let shape: Vec<usize> = shape.into_iter().map(|d| d as usize).collect();
        let start = offset as usize;
        let bytes = self.bytes[start..start + bytes_needed as usize].to_vec();
        Ok(Field { name, dtype, shape, bytes })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tensor file with the given fields (name, dtype code, shape, data bytes).
    pub(crate) fn build(fields: &[(&str, u8, Vec<u64>, Vec<u8>)]) -> Vec<u8> {
        let header: usize = PREAMBLE
            + fields
                .iter()
                .map(|(n, _, s, _)| 2 + n.len() + 2 + 1 + 8 + 8 * s.len())
                .sum::<usize>();
        let mut out = Vec::new();
        out.extend(MAGIC);
        out.extend(VERSION);
        out.extend((fields.len() as u32).to_le_bytes());
        let mut offset = header as u64;
        for (name, code, shape, data) in fields {
            out.extend((name.len() as u16).to_le_bytes());
            out.extend(name.as_bytes());
            out.extend((shape.len() as u16).to_le_bytes());
            out.push(*code);
            out.extend(offset.to_le_bytes());
            for d in shape {
                out.extend(d.to_le_bytes());
            }
            offset += data.len() as u64;
        }
        for (_, _, _, data) in fields {
            out.extend(data);
        }
        out
    }

    fn message(r: Result<TensorFile>) -> String {
        r.err().map(|e| e.to_string()).unwrap_or_default()
    }

    #[test]
    fn every_dtype_reads() {
        let mut fields = Vec::new();
        for code in 1..=11u8 {
            let dtype = Dtype::from_code(code).expect("code");
            assert_eq!(dtype.code(), code);
            let data: Vec<u8> = match dtype {
                Dtype::U8 => vec![7, 250],
                Dtype::I8 => vec![7, (-6i8) as u8],
                Dtype::U16 => [7u16, 65000].iter().flat_map(|v| v.to_le_bytes()).collect(),
                Dtype::I16 => [7i16, -6].iter().flat_map(|v| v.to_le_bytes()).collect(),
                Dtype::U32 => [7u32, 4_000_000_000].iter().flat_map(|v| v.to_le_bytes()).collect(),
                Dtype::I32 => [7i32, -6].iter().flat_map(|v| v.to_le_bytes()).collect(),
                Dtype::U64 => [7u64, 1 << 40].iter().flat_map(|v| v.to_le_bytes()).collect(),
                Dtype::I64 => [7i64, -6].iter().flat_map(|v| v.to_le_bytes()).collect(),
                Dtype::F16 => [half::f16::from_f32(7.0), half::f16::from_f32(-0.5)]
                    .iter()
                    .flat_map(|v| v.to_le_bytes())
                    .collect(),
                Dtype::F32 => [7f32, -0.5].iter().flat_map(|v| v.to_le_bytes()).collect(),
                Dtype::F64 => [7f64, -0.5].iter().flat_map(|v| v.to_le_bytes()).collect(),
            };
            fields.push((format!("f{code}"), code, vec![1u64, 2], data));
        }
        let refs: Vec<(&str, u8, Vec<u64>, Vec<u8>)> =
            fields.iter().map(|(n, c, s, d)| (n.as_str(), *c, s.clone(), d.clone())).collect();
        let t = TensorFile::parse("mem.bsdf", &build(&refs)).expect("parses");
        let second =
            [250.0, -6.0, 65000.0, -6.0, 4e9, -6.0, (1u64 << 40) as f64, -6.0, -0.5, -0.5, -0.5];
        for (code, want) in (1..=11u8).zip(second) {
            let f = t.field(&format!("f{code}")).expect("field");
            assert_eq!(f.shape(), &[1, 2]);
            assert_eq!(f.to_f64(), vec![7.0, want], "dtype {code}");
        }
        assert_eq!(t.field("f10").and_then(Field::to_f32), Some(vec![7.0, -0.5]));
        assert_eq!(t.field("f11").and_then(Field::to_f32), None);
    }

    #[test]
    fn bad_headers_are_errors_naming_file_and_field() {
        let good = build(&[("rgb", 10, vec![2, 3], vec![0u8; 24])]);
        assert!(TensorFile::parse("x.bsdf", &good).is_ok());
        // Truncated anywhere.
        for cut in [0, 5, 17, 20, 30, good.len() - 1] {
            let m = message(TensorFile::parse("x.bsdf", &good[..cut]));
            assert!(
                m.starts_with("x.bsdf: ")
                    && (m.contains("truncated") || m.contains("beyond") || m.contains("more than")),
                "{cut}: {m}"
            );
        }
        // Wrong magic, wrong version.
        let mut bad = good.clone();
        bad[0] = b'T';
        assert!(message(TensorFile::parse("x.bsdf", &bad)).contains("magic"));
        let mut bad = good.clone();
        bad[12] = 2;
        assert!(message(TensorFile::parse("x.bsdf", &bad)).contains("version 2.0"));
        // Declared size beyond the file: a huge dimension (no allocation happens).
        let huge = build(&[("rgb", 10, vec![1 << 40, 1 << 30], vec![0u8; 24])]);
        let m = message(TensorFile::parse("x.bsdf", &huge));
        assert!(m.contains("\"rgb\"") && m.contains("beyond the end"), "{m}");
        // Absurd field count and rank.
        let mut bad = good.clone();
        bad[14..18].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(message(TensorFile::parse("x.bsdf", &bad)).contains("fields"));
        let mut bad = good.clone();
        let rank_at = PREAMBLE + 2 + 3;
        bad[rank_at..rank_at + 2].copy_from_slice(&u16::MAX.to_le_bytes());
        let m = message(TensorFile::parse("x.bsdf", &bad));
        assert!(m.contains("\"rgb\"") && m.contains("rank 65535"), "{m}");
        // Unknown dtype.
        let mut bad = good.clone();
        bad[rank_at + 2] = 12;
        assert!(message(TensorFile::parse("x.bsdf", &bad)).contains("unknown dtype code 12"));
        // Duplicate names.
        let dup = build(&[("a", 1, vec![1], vec![0]), ("a", 1, vec![1], vec![0])]);
        assert!(message(TensorFile::parse("x.bsdf", &dup)).contains("twice"));
    }

    #[test]
    fn f32_fields_are_checked() {
        let data: Vec<u8> = [1f32, f32::NAN].iter().flat_map(|v| v.to_le_bytes()).collect();
        let t = TensorFile::parse("n.bsdf", &build(&[("ndf", 10, vec![2], data)])).expect("parse");
        let m = t.f32_field("ndf", 1).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(m.contains("n.bsdf") && m.contains("\"ndf\"") && m.contains("NaN"), "{m}");
        let m = t.f32_field("ndf", 2).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(m.contains("rank 1, expected 2"), "{m}");
        let m = t.f32_field("rgb", 1).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(m.contains("no field \"rgb\""), "{m}");
    }
}
