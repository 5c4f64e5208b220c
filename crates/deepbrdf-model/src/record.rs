//! Burnpack weights records (Burn's record format) outside a network: reading one safely, and
//! rewriting one (renaming its parameter paths, dropping its parameter ids).

use burn::store::ModuleRecord;
use burn::tensor::Bytes;

/// The record in `bytes`, for loading into a network whose parameters are all floats. Burn
/// panics when a stored tensor is of an integer or boolean type (a damaged file: found by
/// fuzzing the model artifact), so such a record is refused here first.
pub(crate) fn float_record(bytes: Vec<u8>) -> Result<ModuleRecord, String> {
    let bytes = Bytes::from_bytes_vec(bytes);
    let tensors = burn_pack::Reader::from_bytes(bytes.clone())
        .and_then(|reader| reader.into_tensors())
        .map_err(|e| format!("not a weights record: {e}"))?;
    if let Some(t) = tensors.iter().find(|t| !t.dtype.is_float()) {
        return Err(format!("tensor {} is stored as {:?}, not as floats", t.name, t.dtype));
    }
    ModuleRecord::from_bytes(bytes).map_err(|e| e.to_string())
}

/// `bytes` (a burnpack record) with every parameter path passed through `rename` and, without
/// `keep_ids`, no parameter ids. Burn draws ids at random when a network is built; they tie a
/// checkpoint's optimizer state to its parameters and mean nothing in a saved model, where
/// they would make the same weights differ in their bytes from run to run.
pub(crate) fn rewrite(
    bytes: Vec<u8>,
    keep_ids: bool,
    rename: impl Fn(String) -> String,
) -> Result<Vec<u8>, String> {
    let reader = burn_pack::Reader::from_bytes(Bytes::from_bytes_vec(bytes))
        .map_err(|e| format!("not a weights record: {e}"))?;
    let tensors = reader.into_tensors().map_err(|e| format!("bad weights record: {e}"))?;
    let rewritten = tensors
        .into_iter()
        .map(|t| {
            let (name, dtype, shape, id, data) =
                t.into_parts().map_err(|e| format!("bad weights record: {e}"))?;
            let id = id.filter(|_| keep_ids);
            Ok(burn_pack::Tensor::new(rename(name), dtype, shape, id, data))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let bytes = burn_pack::Writer::new(rewritten)
        .into_bytes()
        .map_err(|e| format!("cannot rewrite the weights record: {e}"))?;
    Ok(bytes.to_vec())
}
