//! Writing the RGL "tensor file" container (the format [`super::tensor`] reads: magic, version
//! 1.0, field count, the field descriptions, then the data). Every field's data starts at a
//! multiple of 8 bytes, as in the RGL database's files, so readers that map the file (Mitsuba's
//! `TensorFile`) see aligned arrays. Written through a temporary file renamed over the target,
//! so a reader never sees a partial file.

use super::tensor::{Dtype, Field, TensorFile, MAGIC, VERSION};
use crate::error::{DataError, Result};
use crate::files::write_atomic;
use std::path::{Path, PathBuf};

/// Alignment of every field's data in the files written here.
const ALIGN: usize = 8;

impl Field {
    /// A field of f32 `values` with dimensions `shape` (slowest first); errors if the product
    /// of the dimensions is not the number of values.
    pub fn from_f32(name: &str, shape: &[usize], values: &[f32]) -> Result<Self> {
        let bytes = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        Self::from_parts(name, Dtype::F32, shape, bytes)
    }

    /// A field of u8 `values` with dimensions `shape`.
    pub fn from_u8(name: &str, shape: &[usize], values: &[u8]) -> Result<Self> {
        Self::from_parts(name, Dtype::U8, shape, values.to_vec())
    }

    /// A field of u32 `values` with dimensions `shape`.
    pub fn from_u32(name: &str, shape: &[usize], values: &[u32]) -> Result<Self> {
        let bytes = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        Self::from_parts(name, Dtype::U32, shape, bytes)
    }

    fn from_parts(name: &str, dtype: Dtype, shape: &[usize], bytes: Vec<u8>) -> Result<Self> {
        let count = shape.iter().try_fold(1usize, |n, &d| n.checked_mul(d));
        if count.and_then(|n| n.checked_mul(dtype.size())) != Some(bytes.len())
            || name.len() > usize::from(u16::MAX)
            || shape.len() > usize::from(u16::MAX)
        {
            return Err(DataError::Invalid(format!(
                "tensor field {name:?}: shape {shape:?} of {dtype:?} does not hold {} bytes",
                bytes.len()
            )));
        }
        Ok(Self::new_unchecked(name.to_owned(), dtype, shape.to_vec(), bytes))
    }
}

impl TensorFile {
    /// A tensor file of `fields` (names must be distinct); `path` names it in errors and is
    /// where [`TensorFile::write`] puts it.
    pub fn from_fields(path: impl Into<PathBuf>, fields: Vec<Field>) -> Result<Self> {
        let path = path.into();
        for (i, f) in fields.iter().enumerate() {
            if fields[..i].iter().any(|g| g.name() == f.name()) {
                return Err(DataError::format(&path, format!("field {:?} twice", f.name())));
            }
        }
        Ok(Self::new_unchecked(path, fields))
    }

    /// The file's bytes: the header, then each field's data at the next multiple of 8 bytes
    /// (zero padding between).
    pub fn to_bytes(&self) -> Vec<u8> {
        let fields = self.fields();
        let header: usize = 12
            + 2
            + 4
            + fields
                .iter()
                .map(|f| 2 + f.name().len() + 2 + 1 + 8 + 8 * f.shape().len())
                .sum::<usize>();
        let align = |n: usize| n.div_ceil(ALIGN) * ALIGN;
        let mut offsets = Vec::with_capacity(fields.len());
        let mut end = align(header);
        for f in fields {
            offsets.push(end);
            end = align(end + f.bytes().len());
        }
        let mut out = Vec::with_capacity(end);
        out.extend(MAGIC);
        out.extend(VERSION);
        out.extend((fields.len() as u32).to_le_bytes());
        for (f, &offset) in fields.iter().zip(&offsets) {
            out.extend((f.name().len() as u16).to_le_bytes());
            out.extend(f.name().as_bytes());
            out.extend((f.shape().len() as u16).to_le_bytes());
            out.push(f.dtype().code());
            out.extend((offset as u64).to_le_bytes());
            for &d in f.shape() {
                out.extend((d as u64).to_le_bytes());
            }
        }
        for (f, &offset) in fields.iter().zip(&offsets) {
            out.resize(offset, 0);
            out.extend(f.bytes());
        }
        out.resize(end, 0);
        out
    }

    /// Writes the file to `path` atomically (temporary file, then rename).
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        write_atomic(path.as_ref(), &self.to_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_files_read_back_field_for_field() {
        let fields = vec![
            Field::from_u8("description", &[5], b"hello").expect("u8"),
            Field::from_f32("theta_i", &[3], &[0.0, 0.5, 1.5]).expect("f32"),
            Field::from_f32("rgb", &[1, 3, 2], &[1.0, -2.0, 3.0, 4.0, 5.0, 6.5]).expect("f32"),
            Field::from_u32("version", &[2], &[1, 0]).expect("u32"),
        ];
        let t = TensorFile::from_fields("mem.bsdf", fields).expect("fields");
        let bytes = t.to_bytes();
        let back = TensorFile::parse("mem.bsdf", &bytes).expect("reads back");
        assert_eq!(back, t);
        // Written atomically, padded to a multiple of 8 bytes.
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("t.bsdf");
        t.write(&path).expect("write");
        assert_eq!(std::fs::read(&path).expect("read"), bytes);
        assert_eq!(bytes.len() % ALIGN, 0);
    }

    #[test]
    fn bad_fields_are_refused() {
        assert!(Field::from_f32("x", &[2, 2], &[1.0; 3]).is_err());
        assert!(Field::from_u8("x", &[usize::MAX, 2], &[0; 4]).is_err());
        let a = Field::from_u8("a", &[1], &[0]).expect("a");
        let m = TensorFile::from_fields("d.bsdf", vec![a.clone(), a]).expect_err("twice");
        assert!(m.to_string().contains("d.bsdf") && m.to_string().contains("twice"), "{m}");
    }
}
