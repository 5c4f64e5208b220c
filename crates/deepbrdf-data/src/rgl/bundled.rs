//! The seven real isotropic RGL measurements bundled in the crate (CC0, from the RGL material
//! database of Dupuy & Jakob 2018 via the public repository `adenine-dev/luminiferous`), as the
//! collection `rgl-measured`: raw `.bsdf` tensor files embedded with `include_bytes!`, so they
//! work offline. `rgl` (in [`crate::bundled`]) names the NBRDF fits of the RGL materials; the
//! file names here are those fits' names, so `rgl/<name>` and `rgl-measured/<name>` are the fit
//! and the measurement of the same material.

use super::RglBrdf;
use crate::error::{DataError, Result};
use std::path::Path;

/// The collection's name.
pub const COLLECTION: &str = "rgl-measured";

/// (name, bytes) of every bundled measurement, sorted by name.
pub const FILES: [(&str, &[u8]); 7] = [
    ("cc_ibiza_sunset_rgb", include_bytes!("../../assets/rgl-measured/cc_ibiza_sunset_rgb.bsdf")),
    (
        "cc_iris_purple_gem_rgb",
        include_bytes!("../../assets/rgl-measured/cc_iris_purple_gem_rgb.bsdf"),
    ),
    ("cg_sunflower_rgb", include_bytes!("../../assets/rgl-measured/cg_sunflower_rgb.bsdf")),
    (
        "colodur_napoli_4f_rgb",
        include_bytes!("../../assets/rgl-measured/colodur_napoli_4f_rgb.bsdf"),
    ),
    ("paper_white_rgb", include_bytes!("../../assets/rgl-measured/paper_white_rgb.bsdf")),
    ("satin_rosaline_rgb", include_bytes!("../../assets/rgl-measured/satin_rosaline_rgb.bsdf")),
    (
        "vch_golden_yellow_rgb",
        include_bytes!("../../assets/rgl-measured/vch_golden_yellow_rgb.bsdf"),
    ),
];

/// The names of the bundled measurements, sorted.
pub fn names() -> Vec<&'static str> {
    FILES.iter().map(|(n, _)| *n).collect()
}

/// The raw bytes of the bundled measurement `name`, if there is one.
pub fn bytes(name: &str) -> Option<&'static [u8]> {
    FILES.iter().find(|(n, _)| *n == name).map(|(_, b)| *b)
}

/// The evaluator of the bundled measurement `name`; an error lists the names if it is unknown.
pub fn load(name: &str) -> Result<RglBrdf> {
    let bytes = bytes(name).ok_or_else(|| {
        DataError::Invalid(format!(
            "no measurement named {name:?} in {COLLECTION}: expected one of {}",
            names().join(", ")
        ))
    })?;
    RglBrdf::parse(Path::new(&format!("<bundled {COLLECTION}/{name}.bsdf>")), bytes)
}
