//! `experiments round-trip [MEASUREMENT...]`: the round trip of real RGL measurements through
//! the project's formats (`deepbrdf_eval::round_trip`): each measurement converted to the MERL
//! grid, exported back to an RGL file at each `--resolution`, and rendered by the project's
//! evaluator; prints a table of image RelAE against the original measurement beside the MERL
//! table's own and the bar of `export-bsdf` (at most 1.5 times the table's own). Default: the
//! seven bundled `rgl-measured` measurements, in `compare`'s scene.
use crate::args::data::CacheArg;
use crate::args::measurement::load_evaluator;
use crate::args::scene::SceneArgs;
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::rgl::{bundled, ExportResolution};
use deepbrdf_data::Progress;
use deepbrdf_eval::round_trip::{round_trip, Stage};

/// The bar: an export's RelAE at most this many times the MERL table's own.
const BAR: f64 = 1.5;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Measurements: `rgl-measured/NAME` (bundled) or RGL `.bsdf` files (default: every
    /// bundled measurement).
    pub measurements: Vec<String>,
    /// An export resolution, `THETA_I,NDF,VNDF,RGB` (repeat for several; default the database's
    /// 8,128,128,32 and `export-bsdf`'s default, 64,128,32,160).
    #[arg(long = "resolution", value_name = "T,N,V,R", value_parser = parse_resolution)]
    pub resolutions: Vec<ExportResolution>,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub cache: CacheArg,
}

fn parse_resolution(s: &str) -> Result<ExportResolution, String> {
    let n: Vec<usize> = s
        .split(',')
        .map(|v| v.trim().parse().map_err(|e| format!("'{v}' in '{s}': {e}")))
        .collect::<Result<_, _>>()?;
    let [theta_i, ndf, vndf, rgb] = n[..] else {
        return Err(format!("'{s}': expected THETA_I,NDF,VNDF,RGB (four numbers)"));
    };
    let resolution = ExportResolution { theta_i, ndf, vndf, rgb };
    resolution.validate().map_err(|e| e.to_string())?;
    Ok(resolution)
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let setup = args.scene.setup(256)?;
    let cache = args.cache.cache();
    let resolutions = match args.resolutions.is_empty() {
        true => vec![ExportResolution::RGL_DATABASE, ExportResolution::default()],
        false => args.resolutions.clone(),
    };
    let specs: Vec<String> = match args.measurements.is_empty() {
        true => bundled::names().iter().map(|n| format!("{}/{n}", bundled::COLLECTION)).collect(),
        false => args.measurements.clone(),
    };
    let stage = Stage { scene: &setup.scene, settings: &setup.settings, tonemap: &setup.tonemap };
    let label = |r: &ExportResolution| format!("{},{},{},{}", r.theta_i, r.ndf, r.vndf, r.rgb);
    println!("Round trip measurement -> MERL -> .bsdf, image RelAE against the measurement's evaluator ({}):\n", setup.description());
    let mut header = String::from("| measurement | MERL table | bar (1.5x) |");
    let mut rule = String::from("| --- | ---: | ---: |");
    for r in &resolutions {
        header.push_str(&format!(" export {} |", label(r)));
        rule.push_str(" ---: |");
    }
    println!("{header}\n{rule}");
    let mut met = vec![0usize; resolutions.len()];
    for spec in &specs {
        let measured = load_evaluator(spec, "a measurement", "round-trip")?;
        let (name, table) =
            load_material(spec, &cache).with_context(|| format!("loading '{spec}'"))?;
        let r = round_trip(&name, &measured, &table, &resolutions, &stage, progress)?;
        let bar = BAR * r.table_relae;
        let mut row = format!("| {name} | {:.4} | {bar:.4} |", r.table_relae);
        for (i, e) in r.export_relae.iter().enumerate() {
            let ok = *e <= bar;
            met[i] += usize::from(ok);
            row.push_str(&format!(" {e:.4} ({}) |", if ok { "met" } else { "not met" }));
        }
        println!("{row}");
    }
    println!();
    for (r, met) in resolutions.iter().zip(met) {
        println!("export {}: bar met on {met} of {} measurements", label(r), specs.len());
    }
    Ok(())
}
