//! `experiments bench convert`: times converting RGL measurements (`.bsdf`) to the MERL grid,
//! no cache (target: at most 10 s per file on 2 cores). Default: the seven bundled
//! `rgl-measured` files.
use deepbrdf_data::rgl::{bundled, tabulate, RglBrdf};
use deepbrdf_data::Progress;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// `.bsdf` files to convert instead of the bundled measurements.
    pub files: Vec<PathBuf>,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let inputs: Vec<(String, Vec<u8>)> = if args.files.is_empty() {
        bundled::files()?.into_iter().map(|(n, b)| (n.to_string(), b)).collect()
    } else {
        args.files
            .iter()
            .map(|p| Ok((p.display().to_string(), std::fs::read(p)?)))
            .collect::<std::io::Result<_>>()?
    };
    progress.start(inputs.len() as u64, "bench convert");
    let mut rows = Vec::new();
    for (name, bytes) in &inputs {
        let t = Instant::now();
        let brdf = RglBrdf::parse(Path::new(name), bytes)?;
        let parse = t.elapsed().as_secs_f64();
        let table = tabulate(&brdf)?;
        rows.push((name.clone(), parse, t.elapsed().as_secs_f64(), table.valid_cells()));
        progress.advance(1);
    }
    progress.finish();
    println!("converted {} files on {} threads", rows.len(), rayon::current_num_threads());
    for (name, parse, total, valid) in &rows {
        println!("{name}: {total:.2} s (parse {parse:.3} s), {valid} valid cells");
    }
    let worst = rows.iter().map(|r| r.2).fold(0.0, f64::max);
    println!("slowest {worst:.2} s per file (target: <= 10 s on 2 cores)");
    Ok(())
}
