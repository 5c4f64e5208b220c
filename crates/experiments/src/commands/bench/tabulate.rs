//! `experiments bench tabulate`: times tabulating bundled NBRDF networks onto the MERL grid, with
//! no cache (target: all 100 `merl` materials in under 30 s on 2 cores).
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::nbrdf::tabulate;
use deepbrdf_data::Progress;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Bundled collection to take the networks from.
    #[arg(long, value_name = "NAME", default_value = "merl")]
    pub collection: Collection,
    /// Number of materials to tabulate (default: the whole collection).
    #[arg(long, short = 'n', value_parser = clap::value_parser!(u32).range(1..))]
    pub count: Option<u32>,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let networks = args.collection.materials()?;
    let n = args.count.map_or(networks.len(), |c| (c as usize).min(networks.len()));
    progress.start(n as u64, "bench tabulate");
    let mut seconds = Vec::with_capacity(n);
    let mut valid = 0usize;
    for net in &networks[..n] {
        let t = Instant::now();
        let table = tabulate(net)?;
        seconds.push(t.elapsed().as_secs_f64());
        valid += table.valid_cells();
        progress.advance(1);
    }
    progress.finish();
    let total: f64 = seconds.iter().sum();
    seconds.sort_by(f64::total_cmp);
    println!(
        "tabulated {n} {} materials on {} threads ({} valid cells each on average)",
        args.collection,
        rayon::current_num_threads(),
        valid / n
    );
    println!(
        "per material: mean {:.3} s, median {:.3} s, min {:.3} s, max {:.3} s",
        total / n as f64,
        seconds[(n - 1) / 2],
        seconds[0],
        seconds[n - 1]
    );
    println!(
        "total {total:.2} s ({:.1} M cells/s; target for 100 materials: < 30 s)",
        valid as f64 / total / 1e6
    );
    Ok(())
}
