//! `experiments attributes`: estimates the 7 editable attributes of §5.1 (Hu et al. 2020;
//! diffuse albedo RGB, specular albedo RGB, GGX roughness: `deepbrdf_eval::attributes`) of every
//! material of a dataset or of the named materials, writes them as CSV (atomically) and prints a
//! table; `--relae` also measures the image RelAE of each analytic fit against its measurement.
use crate::args::data::DataArgs;
use anyhow::{bail, Context};
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::attributes::{self, AttributeRow, FitConfig};
use deepbrdf_eval::metrics::{ImageRelae, ImageRelaeConfig};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// MERL .binary files or bundled materials; when none is given, the dataset of
    /// --collection / --data.
    pub materials: Vec<String>,
    /// Output CSV [default: results/attributes-<dataset>.csv].
    #[arg(short, long, value_name = "CSV")]
    pub output: Option<PathBuf>,
    /// Also render each fit and its measurement (the harness's preview sphere under sun and sky,
    /// 128 px, 16 spp) and report their image RelAE (~0.3 s of CPU per material).
    #[arg(long)]
    pub relae: bool,
    /// `eps` of the fit's log space, ln(eps + cos_i cos_o f), in 1/sr [default: the library's].
    #[arg(long, value_name = "EPS")]
    pub log_offset: Option<f64>,
    /// Fit only cells with theta_d below DEG degrees [default: the library's].
    #[arg(long, value_name = "DEG")]
    pub max_theta_d: Option<f64>,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub data: DataArgs,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let (label, names, tables) = if args.materials.is_empty() {
        let set = args.data.load(progress)?;
        (set.label.clone(), set.names, set.tables)
    } else {
        let cache = args.data.cache();
        let mut names = Vec::new();
        let mut tables: Vec<MerlTable> = Vec::new();
        for spec in &args.materials {
            let (name, table) = load_material(spec, &cache)
                .with_context(|| format!("loading material '{spec}'"))?;
            names.push(name);
            tables.push(table);
        }
        ("materials".to_string(), names, tables)
    };
    let output = args.output.clone().unwrap_or_else(|| {
        let stem: String =
            label.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect();
        PathBuf::from("results").join(format!("attributes-{stem}.csv"))
    });
    if output.exists() && !args.force {
        bail!("{} exists; pass --force to replace it", output.display());
    }
    if let Some(dir) = output.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut config = FitConfig::default();
    if let Some(eps) = args.log_offset {
        config.offset = eps;
    }
    if let Some(deg) = args.max_theta_d {
        config.max_theta_d_deg = deg;
    }
    let started = Instant::now();
    progress.start(tables.len() as u64, "fitting attributes");
    let mut rows = Vec::with_capacity(tables.len());
    for (name, table) in names.iter().zip(&tables) {
        let t = Instant::now();
        let fit = attributes::fit(table, &config).with_context(|| format!("fitting {name}"))?;
        let seconds = t.elapsed().as_secs_f64();
        let image_relae = match args.relae {
            true => {
                let measured = ImageRelae::new(table, &ImageRelaeConfig::default())
                    .with_context(|| format!("rendering {name}"))?;
                Some(measured.measure(&fit.attributes.table())?)
            }
            false => None,
        };
        rows.push(AttributeRow { material: name.clone(), fit, image_relae, seconds });
        progress.advance(1);
    }
    progress.finish();
    attributes::write_csv(&output, &rows)?;
    println!("{}", attributes::markdown(&rows));
    println!("{label}: {}", attributes::summary(&rows));
    println!(
        "whole command {:.1} s; attributes written to {}",
        started.elapsed().as_secs_f64(),
        output.display()
    );
    Ok(())
}
