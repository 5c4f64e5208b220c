//! A material given as a real RGL measurement, for `compare --evaluator[-a]` and
//! `round-trip`: a `.bsdf` file or a bundled `rgl-measured/NAME`.
use anyhow::bail;
use deepbrdf_data::rgl::{bundled, RglBrdf};

/// The RGL evaluator of `spec` (material `which`, A or B, for `flag`): a `.bsdf` file or
/// `rgl-measured/NAME`.
pub fn load_evaluator(spec: &str, which: &str, flag: &str) -> anyhow::Result<RglBrdf> {
    match spec.strip_prefix("rgl-measured/") {
        Some(name) => Ok(bundled::load(name)?),
        None if spec.ends_with(".bsdf") => Ok(RglBrdf::read(spec)?),
        None => bail!("{flag} needs a .bsdf file or rgl-measured/NAME as {which}, not '{spec}'"),
    }
}
