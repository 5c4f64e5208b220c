//! `experiments tabulate`: writes MERL `.binary` files tabulated from the bundled NBRDF networks
//! (a whole collection, or one material), through the table cache. An existing file with other
//! content is never overwritten without `--force`; identical files are left as they are.
use crate::args::data::CacheArg;
use anyhow::bail;
use deepbrdf_data::bundled::{find_material, Collection};
use deepbrdf_data::merl::io::{write_merl, MerlFile};
use deepbrdf_data::nbrdf::Network;
use deepbrdf_data::Progress;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Bundled collection to tabulate: merl (100), nielsen2015 (8) or rgl (51).
    #[arg(long, value_name = "NAME", default_value = "merl", conflicts_with = "material")]
    pub collection: Collection,
    /// Tabulate only this bundled material (`chrome`, `merl/chrome`, `rgl/cardboard_rgb`).
    #[arg(long, value_name = "NAME")]
    pub material: Option<String>,
    /// Output folder; files are named `<material>.binary`.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Overwrite existing files whose content differs.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// What happened to one output file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Written {
    New,
    Replaced,
    Unchanged,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let networks: Vec<&Network> = match &args.material {
        Some(spec) => vec![find_material(spec)?.1],
        None => args.collection.materials()?.iter().collect(),
    };
    if args.out.exists() && !args.out.is_dir() {
        bail!("{}: exists and is not a directory", args.out.display());
    }
    // Creates the folder; held until the end: a second run on the same folder is refused.
    let _lock = deepbrdf_data::lock::FolderLock::acquire(&args.out)?;
    let cache = args.cache.cache();
    let start = Instant::now();
    let label = args.material.clone().unwrap_or_else(|| args.collection.to_string());
    progress.start(networks.len() as u64, &format!("tabulating {label}"));
    let outcomes = networks
        .par_iter()
        .map(|net| {
            let path = args.out.join(format!("{}.binary", net.name()));
            let table = cache.tabulated(net)?;
            let written = write_unless_different(&table, &path, args.force)?;
            progress.advance(1);
            Ok(written)
        })
        .collect::<anyhow::Result<Vec<Written>>>();
    progress.finish();
    let outcomes = outcomes?;
    let count = |w: Written| outcomes.iter().filter(|&&o| o == w).count();
    println!(
        "{} MERL files in {}: {} new, {} replaced, {} unchanged ({:.1} s)",
        outcomes.len(),
        args.out.display(),
        count(Written::New),
        count(Written::Replaced),
        count(Written::Unchanged),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Writes `table` to `path` (atomically), unless a file with the same content is there. A file
/// with other (or unreadable) content is an error without `force`.
fn write_unless_different(
    table: &deepbrdf_data::MerlTable,
    path: &Path,
    force: bool,
) -> anyhow::Result<Written> {
    let existed = path.exists();
    if existed {
        let same = MerlFile::read(path)
            .map(|old| old.stored() == MerlFile::from_table(table).stored())
            .unwrap_or(false);
        if same {
            return Ok(Written::Unchanged);
        }
        if !force {
            bail!(
                "{}: exists with other content; not overwriting it (pass --force to replace it)",
                path.display()
            );
        }
    }
    write_merl(table, path)?;
    Ok(if existed { Written::Replaced } else { Written::New })
}
