//! `experiments reconstruct [--model DIR] FILE_OR_MATERIAL -o out.binary [--slices 1/3|1/9]`: encode and
//! decode a BRDF; with `--slices`, from the reduced input of Fig. 2 (every 3rd or 9th phi_d
//! slice, each missing slice filled from its nearest kept one).
use anyhow::bail;
use anyhow::Context;
use deepbrdf_data::augment::{kept_slices, SliceSelection};
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::mapping::log_relative;
use deepbrdf_data::merl::write_merl;
use deepbrdf_data::Progress;
use deepbrdf_model::DeepBrdf;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: crate::args::model::ModelMaterialArg,
    /// The MERL .binary file to write.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Use only this fraction of the phi_d slices as input (Fig. 2): 1/3 or 1/9 (any 1/N).
    #[arg(long, value_name = "1/N")]
    pub slices: Option<String>,
    #[command(flatten)]
    pub refine: crate::args::refine::RefineArg,
    #[command(flatten)]
    pub cache: crate::args::data::CacheArg,
}

/// Parses `1/N` into every-N-th slice selection.
fn parse_fraction(s: &str) -> anyhow::Result<SliceSelection> {
    let n = s
        .trim()
        .strip_prefix("1/")
        .and_then(|n| n.trim().parse::<usize>().ok())
        .filter(|n| (1..=180).contains(n));
    match n {
        Some(n) => Ok(SliceSelection::Every(n)),
        None => bail!("--slices {s:?}: expected 1/N with N in 1..=180, e.g. 1/3 or 1/9"),
    }
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let (model_dir, input) = args.input.resolve()?;
    let model = DeepBrdf::load(&model_dir, &device)?.with_refinement(args.refine.refinement()?);
    let (name, table) = load_material(&input, &args.cache.cache())
        .with_context(|| format!("cannot read {input}"))?;
    let latent = match &args.slices {
        Some(fraction) => {
            let kept = kept_slices(&parse_fraction(fraction)?, 0);
            model.encode_partial(&table, &kept)?
        }
        None => model.encode(&table)?,
    };
    let out = model.decode(&latent)?;
    // Mapped-space MSE over the cells valid in both (the error Fig. 3 reports).
    let reference = model.reference().values();
    let (mut sum, mut count) = (0f64, 0usize);
    let (a, b) = (table.values(), out.values());
    let cells = a.len() / 3;
    for cell in 0..cells {
        if table.is_valid(cell) && out.is_valid(cell) {
            for c in 0..3 {
                let i = c * cells + cell;
                let r = f64::from(reference[i]);
                let d = log_relative(f64::from(a[i]), r) - log_relative(f64::from(b[i]), r);
                sum += d * d;
                count += 1;
            }
        }
    }
    write_merl(&out, &args.output)?;
    println!(
        "{name}: k = {}, mapped-space MSE {:.4e}{}; wrote {}",
        model.k(),
        sum / count.max(1) as f64,
        args.slices.as_ref().map(|s| format!(" from {s} of the slices")).unwrap_or_default(),
        args.output.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_parse() {
        assert_eq!(parse_fraction("1/3").unwrap(), SliceSelection::Every(3));
        assert_eq!(parse_fraction(" 1/9").unwrap(), SliceSelection::Every(9));
        assert!(parse_fraction("2/3").is_err());
        assert!(parse_fraction("1/0").is_err());
        assert!(parse_fraction("1/181").is_err());
    }
}
