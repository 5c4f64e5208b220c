//! The on-disk form of a fitted [`BaselineBasis`]: a fixed little-endian header, the payload,
//! and a SHA-256 of everything before it.
//!
//! ```text
//! magic    8 bytes  "DBRDFLB1"
//! kind     u32      0 = log (PCA), 1 = log-relative (IPCA)
//! name_len u32      then name_len bytes of UTF-8 (at most 64)
//! n_train  u64
//! cells    u64      domain cells (<= 1,458,000); dim = 3 * cells
//! k        u64      components (<= 4096)
//! cells    u32 x cells
//! mean     f32 x dim
//! sigma    f64 x k
//! V        f32 x dim*k  (row-major, dim x k)
//! ref      f32 x dim    (IPCA only; the cosine weights are recomputed from the grid)
//! sha256   32 bytes
//! ```
//! Loading checks, in this order, before anything large is allocated: the magic, the mapping
//! kind, the name length, the sizes (domain cells <= the grid's, 1 <= k < n_train, k <= 4096),
//! and that the file's length is exactly what the header implies; then the whole file is read
//! and its SHA-256 compared before any value is interpreted.

use super::{BaselineBasis, Domain, Mapping};
use crate::error::{EvalError, Result};
use crate::pca::LinearBasis;
use deepbrdf_data::merl::CELLS;
use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::Path;

const MAGIC: &[u8; 8] = b"DBRDFLB1";
const MAX_NAME: usize = 64;
const MAX_K: usize = 4096;

pub(super) fn save(b: &BaselineBasis, path: &Path) -> Result<()> {
    let name = b.name.as_bytes();
    if name.len() > MAX_NAME {
        return Err(EvalError::Invalid(format!("basis name longer than {MAX_NAME} bytes")));
    }
    if let Mapping::LogRelative { epsilon, .. } = b.mapping {
        if epsilon != crate::ipca::EPSILON {
            return Err(EvalError::Invalid(format!(
                "a basis artifact holds IPCA's eps {}, not {epsilon}",
                crate::ipca::EPSILON
            )));
        }
    }
    let mut out: Vec<u8> = Vec::new();
    out.extend_from_slice(MAGIC);
    let kind: u32 = match b.mapping {
        Mapping::Log => 0,
        Mapping::LogRelative { .. } => 1,
    };
    out.extend_from_slice(&kind.to_le_bytes());
    out.extend_from_slice(&(name.len() as u32).to_le_bytes());
    out.extend_from_slice(name);
    out.extend_from_slice(&(b.n_train as u64).to_le_bytes());
    out.extend_from_slice(&(b.domain.cells().len() as u64).to_le_bytes());
    out.extend_from_slice(&(b.basis.k() as u64).to_le_bytes());
    b.domain.cells().iter().for_each(|c| out.extend_from_slice(&c.to_le_bytes()));
    b.basis.mean().iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    b.basis.singular_values().iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    b.basis.components().iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    if let Mapping::LogRelative { reference, .. } = &b.mapping {
        reference.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    }
    let digest = Sha256::digest(&out);
    out.extend_from_slice(&digest);

    Ok(deepbrdf_data::files::write_atomic(path, &out)?)
}

/// Reads little-endian fields from a byte slice, failing with a format error at the end.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
    path: &'a Path,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if self.bytes.len() - self.at < n {
            return Err(EvalError::format(self.path, "truncated basis file"));
        }
        let s = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap_or_default()))
    }
    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap_or_default()))
    }
    fn f32s(&mut self, n: usize) -> Result<Vec<f32>> {
        Ok(self
            .take(4 * n)?
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect())
    }
}

pub(super) fn load(path: &Path) -> Result<BaselineBasis> {
    let mut file = std::fs::File::open(path).map_err(|e| EvalError::io(path, e))?;
    let meta = file.metadata().map_err(|e| EvalError::io(path, e))?;
    if !meta.is_file() {
        return Err(EvalError::format(path, "not a regular file (a basis file was expected)"));
    }
    let size = meta.len();
    // Read the fixed header first; the payload size follows from it.
    let mut head = vec![0u8; 16];
    file.read_exact(&mut head)
        .map_err(|_| EvalError::format(path, "too short to be a DeepBRDF basis file"))?;
    if &head[..8] != MAGIC {
        return Err(EvalError::format(path, "not a DeepBRDF basis file (bad magic)"));
    }
    let kind = u32::from_le_bytes([head[8], head[9], head[10], head[11]]);
    let name_len = u32::from_le_bytes([head[12], head[13], head[14], head[15]]) as usize;
    if kind > 1 {
        return Err(EvalError::format(path, format!("unknown mapping kind {kind}")));
    }
    if name_len > MAX_NAME {
        return Err(EvalError::format(path, format!("name length {name_len} exceeds {MAX_NAME}")));
    }
    let mut rest = vec![0u8; name_len + 24];
    file.read_exact(&mut rest).map_err(|_| EvalError::format(path, "truncated basis header"))?;
    let le = |s: &[u8]| u64::from_le_bytes(s.try_into().unwrap_or_default());
    let n_train = le(&rest[name_len..name_len + 8]);
    let n_cells = le(&rest[name_len + 8..name_len + 16]);
    let k = le(&rest[name_len + 16..name_len + 24]);
    if n_cells == 0 || n_cells > CELLS as u64 {
        return Err(EvalError::format(path, format!("absurd domain size {n_cells} cells")));
    }
    if k == 0 || k > MAX_K as u64 {
        return Err(EvalError::format(path, format!("absurd component count {k}")));
    }
    // n centred rows have rank n - 1 at most, so a fitted basis has k < n_train.
    if n_train < 2 || k >= n_train {
        return Err(EvalError::format(
            path,
            format!("inconsistent header: {k} components from {n_train} training materials"),
        ));
    }
    let (n_cells, k) = (n_cells as usize, k as usize);
    let dim = 3 * n_cells;
    let payload = 4 * n_cells + 4 * dim + 8 * k + 4 * dim * k + if kind == 1 { 4 * dim } else { 0 };
    let expected = (16 + name_len + 24 + payload + 32) as u64;
    if size != expected {
        return Err(EvalError::format(
            path,
            format!("file is {size} bytes, its header implies {expected} (truncated or corrupt)"),
        ));
    }
    let mut bytes = Vec::with_capacity(expected as usize);
    bytes.extend_from_slice(&head);
    bytes.extend_from_slice(&rest);
    file.read_to_end(&mut bytes).map_err(|e| EvalError::io(path, e))?;
    if bytes.len() as u64 != expected {
        return Err(EvalError::format(path, "file changed size while being read"));
    }
    let body = &bytes[..bytes.len() - 32];
    if Sha256::digest(body).as_slice() != &bytes[bytes.len() - 32..] {
        return Err(EvalError::format(path, "checksum mismatch: the basis file is corrupt"));
    }

    let mut r = Reader { bytes: body, at: 16, path };
    let name = String::from_utf8(r.take(name_len)?.to_vec())
        .map_err(|_| EvalError::format(path, "basis name is not UTF-8"))?;
    let _ = (r.u64()?, r.u64()?, r.u64()?);
    let n_train = n_train as usize;
    let cells: Vec<u32> = (0..n_cells).map(|_| r.u32()).collect::<Result<_>>()?;
    let mean = r.f32s(dim)?;
    let sigmas: Vec<f64> = r
        .take(8 * k)?
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
        .collect();
    let components = r.f32s(dim * k)?;
    let bad = |what: &str| EvalError::format(path, format!("{what} contains a non-finite value"));
    if mean.iter().any(|v| !v.is_finite()) {
        return Err(bad("the mean"));
    }
    if components.iter().any(|v| !v.is_finite()) {
        return Err(bad("the components"));
    }
    let domain = Domain::from_cells(cells).map_err(|e| EvalError::format(path, e.to_string()))?;
    let mapping = if kind == 1 {
        let reference = r.f32s(dim)?;
        let weights = deepbrdf_data::merl::grid::cos_weights();
        let w = domain.cells().iter().map(|&c| weights[c as usize]).collect();
        Mapping::log_relative_from_parts(&domain, reference, w)
            .map_err(|e| EvalError::format(path, e.to_string()))?
    } else {
        Mapping::Log
    };
    let basis = LinearBasis::from_parts(dim, k, mean, components, sigmas)
        .map_err(|e| EvalError::format(path, e.to_string()))?;
    Ok(BaselineBasis { name, domain, mapping, basis, n_train })
}
