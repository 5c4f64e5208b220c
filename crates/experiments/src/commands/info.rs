//! `experiments info FILE_OR_MATERIAL`: what a MERL table holds: its header, the fraction of
//! valid cells, per-channel min/median/max over valid cells, and the hemispherical albedo at
//! normal incidence (`deepbrdf_data::summary`).
use crate::args::data::CacheArg;
use anyhow::Context;
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::merl::{CELLS, N_PHI_D, N_THETA_D, N_THETA_H};
use deepbrdf_data::summary::TableSummary;
use deepbrdf_data::Progress;
use std::path::Path;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// A MERL .binary file, or a bundled material: `chrome`, `merl/chrome`, `rgl/cardboard_rgb`.
    #[arg(required_unless_present = "list")]
    pub material: Option<String>,
    /// List the bundled materials instead.
    #[arg(long)]
    pub list: bool,
    #[command(flatten)]
    pub cache: CacheArg,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    if args.list {
        for collection in Collection::ALL {
            for name in collection.names()? {
                println!("{collection}/{name}");
            }
        }
        return Ok(());
    }
    let spec = args.material.unwrap_or_default();
    let cache = args.cache.cache();
    let (name, table) =
        load_material(&spec, &cache).with_context(|| format!("cannot describe {spec}"))?;
    let path = Path::new(&spec);
    println!("material      {name}");
    let measured = spec.starts_with("rgl-measured/") || spec.ends_with(".bsdf");
    if path.is_file() {
        let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
        let format =
            if measured { "RGL .bsdf, converted to the MERL grid" } else { "MERL .binary" };
        println!("source        {} ({len} bytes, {format})", path.display());
    } else if measured {
        println!("source        bundled RGL measurement {spec}, converted to the MERL grid");
    } else {
        println!("source        bundled NBRDF network {spec}, tabulated onto the MERL grid");
    }
    println!(
        "header        {N_THETA_H} x {N_THETA_D} x {N_PHI_D} (theta_h x theta_d x phi_d), 3 channels"
    );
    let s = TableSummary::of(&table);
    println!("valid cells   {} of {CELLS} ({:.2}%)", s.valid_cells, 100.0 * s.valid_fraction);
    println!("reflectance   1/sr, over valid cells");
    println!("              {:>12} {:>12} {:>12}", "red", "green", "blue");
    println!("  min         {:>12.6} {:>12.6} {:>12.6}", s.min[0], s.min[1], s.min[2]);
    println!("  median      {:>12.6} {:>12.6} {:>12.6}", s.median[0], s.median[1], s.median[2]);
    println!("  max         {:>12.6} {:>12.6} {:>12.6}", s.max[0], s.max[1], s.max[2]);
    println!(
        "albedo        {:>12.6} {:>12.6} {:>12.6}   (hemispherical, normal incidence)",
        s.albedo[0], s.albedo[1], s.albedo[2]
    );
    Ok(())
}
