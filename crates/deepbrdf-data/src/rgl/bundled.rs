//! The seven real isotropic RGL measurements bundled in the crate (CC0, from the RGL material
//! database of Dupuy & Jakob 2018 via the public repository `adenine-dev/luminiferous`), as the
//! collection `rgl-measured`: the `.bsdf` tensor files, each compressed as one zstd frame
//! (`zstd -19`, lossless: `zstd -d` gives the original file back), embedded with
//! `include_bytes!`, so they work offline. `rgl` (in [`crate::bundled`]) names the NBRDF fits of the RGL materials; the
//! file names here are those fits' names, so `rgl/<name>` and `rgl-measured/<name>` are the fit
//! and the measurement of the same material.

use super::tensor::MAX_FILE_BYTES;
use super::RglBrdf;
use crate::error::{DataError, Result};
use std::path::PathBuf;

/// The collection's name.
pub const COLLECTION: &str = "rgl-measured";

/// (name, the file as one zstd frame) of every bundled measurement, sorted by name.
const PACKED: [(&str, &[u8]); 7] = [
    (
        "cc_ibiza_sunset_rgb",
        include_bytes!("../../assets/rgl-measured/cc_ibiza_sunset_rgb.bsdf.zst"),
    ),
    (
        "cc_iris_purple_gem_rgb",
        include_bytes!("../../assets/rgl-measured/cc_iris_purple_gem_rgb.bsdf.zst"),
    ),
    ("cg_sunflower_rgb", include_bytes!("../../assets/rgl-measured/cg_sunflower_rgb.bsdf.zst")),
    (
        "colodur_napoli_4f_rgb",
        include_bytes!("../../assets/rgl-measured/colodur_napoli_4f_rgb.bsdf.zst"),
    ),
    ("paper_white_rgb", include_bytes!("../../assets/rgl-measured/paper_white_rgb.bsdf.zst")),
    ("satin_rosaline_rgb", include_bytes!("../../assets/rgl-measured/satin_rosaline_rgb.bsdf.zst")),
    (
        "vch_golden_yellow_rgb",
        include_bytes!("../../assets/rgl-measured/vch_golden_yellow_rgb.bsdf.zst"),
    ),
];

/// The names of the bundled measurements, sorted.
pub fn names() -> Vec<&'static str> {
    PACKED.iter().map(|(n, _)| *n).collect()
}

/// The path errors name for the bundled measurement `name`.
pub fn origin(name: &str) -> PathBuf {
    PathBuf::from(format!("<bundled {COLLECTION}/{name}.bsdf>"))
}

/// The bytes of the `.bsdf` file of the bundled measurement `name`; an error lists the names if
/// it is unknown.
pub fn bytes(name: &str) -> Result<Vec<u8>> {
    let (_, packed) = PACKED.iter().find(|(n, _)| *n == name).ok_or_else(|| {
        DataError::Invalid(format!(
            "no measurement named {name:?} in {COLLECTION}: expected one of {}",
            names().join(", ")
        ))
    })?;
    zstd::bulk::decompress(packed, MAX_FILE_BYTES as usize)
        .map_err(|e| DataError::format(origin(name), format!("a damaged bundled file: {e}")))
}

/// (name, bytes of the `.bsdf` file) of every bundled measurement, sorted by name.
pub fn files() -> Result<Vec<(&'static str, Vec<u8>)>> {
    names().into_iter().map(|name| Ok((name, bytes(name)?))).collect()
}

/// The evaluator of the bundled measurement `name`; an error lists the names if it is unknown.
pub fn load(name: &str) -> Result<RglBrdf> {
    RglBrdf::parse(&origin(name), &bytes(name)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use sha2::{Digest, Sha256};

    /// The SHA-256 of each original `.bsdf` file of the RGL database, sorted by name.
    const ORIGINALS: [&str; 7] = [
        "ce356ec33ac086aa19eb534dbfc21e08c793790c299e2cab660705d40c665f0a",
        "3e87004db0f7395365f93addb21042505e7531935645653b6fa0c7180b021500",
        "ce817d04568c39284908ce89b12989e68d6407ee48fb44f6cc644e7bfdf7c840",
        "8a8d491956c36ab75c1676ee2acc34c550215a3e771ef5b7e3046654359000c1",
        "9d641fbb56358275509b2b1053d1002313e2dabc7b3ec202eb5c5a6943f7b70e",
        "6a9e7bdff6210969d97522cf7e3f615f3cb50ed4022b517eebda17f93b8e20e0",
        "a250881145be70d7a7e628e6485fdace109ecbca1803621184e9bf98269d693f",
    ];

    #[test]
    fn the_embedded_frames_give_back_the_original_files() -> Result<()> {
        let files = files()?;
        assert_eq!(files.len(), ORIGINALS.len());
        for ((name, bytes), sha) in files.iter().zip(ORIGINALS) {
            assert_eq!(hex::encode(Sha256::digest(bytes)), sha, "{name}");
        }
        let e = bytes("nope").err().map(|e| e.to_string()).unwrap_or_default();
        assert!(e.contains("paper_white_rgb"), "{e}");
        Ok(())
    }
}
