//! Rewriting a burnpack weights record (Burn's record format) without loading it into a
//! network: renaming its parameter paths, dropping its parameter ids.

use burn::tensor::Bytes;

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
