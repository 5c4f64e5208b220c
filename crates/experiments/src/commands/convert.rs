//! `experiments convert IN.bsdf -o OUT.binary`: converts a real RGL measurement (a `.bsdf`
//! tensor file, Dupuy & Jakob 2018) to a MERL `.binary` file, values at the MERL bin centres
//! (`deepbrdf_data::rgl::tabulate`). Prints the valid-cell count and the albedo at normal
//! incidence; `--report` also measures what the cell rule changes (the cosine-weighted average
//! of both orderings against their plain average). An existing output is never overwritten
//! without `--force`.
use anyhow::{bail, Context};
use deepbrdf_data::merl::io::write_merl;
use deepbrdf_data::rgl::tabulate::rule_difference;
use deepbrdf_data::rgl::{tabulate, tabulate_with, CellRule, RglBrdf};
use deepbrdf_data::summary::albedo_at_normal_incidence;
use deepbrdf_data::Progress;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The RGL `.bsdf` file (isotropic) to convert.
    pub input: PathBuf,
    /// The MERL `.binary` file to write.
    #[arg(long, short = 'o', value_name = "FILE")]
    pub out: PathBuf,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
    /// Also tabulate with the plain average of both orderings and print how much it differs.
    #[arg(long)]
    pub report: bool,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    if args.out.exists() && !args.force {
        bail!("{}: exists; not overwriting it (pass --force to replace it)", args.out.display());
    }
    let brdf = RglBrdf::read(&args.input)?;
    let start = Instant::now();
    let table = tabulate(&brdf)?;
    let seconds = start.elapsed().as_secs_f64();
    write_merl(&table, &args.out).with_context(|| format!("writing {}", args.out.display()))?;
    let albedo = albedo_at_normal_incidence(&table);
    println!(
        "{} ({}): {} valid cells, albedo at normal incidence {:.4} {:.4} {:.4}; converted in \
         {seconds:.2} s on {} threads; wrote {}",
        args.input.display(),
        brdf.description(),
        table.valid_cells(),
        albedo[0],
        albedo[1],
        albedo[2],
        rayon::current_num_threads(),
        args.out.display()
    );
    if args.report {
        let other = tabulate_with(&brdf, CellRule::MeanOfOrderings)?;
        let d = rule_difference(&table, &other);
        let a2 = albedo_at_normal_incidence(&other);
        println!(
            "cell rule: cosine-weighted vs plain average of both orderings: mean relative \
             difference {:.4}, 99th percentile {:.4}, largest absolute {:.4} 1/sr; albedo with the \
             plain average {:.4} {:.4} {:.4}",
            d.mean_relative, d.p99_relative, d.max_absolute, a2[0], a2[1], a2[2]
        );
    }
    Ok(())
}
