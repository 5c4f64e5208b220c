//! `experiments pack-nbrdf --from DIR --out DIR`: packs the JSON NBRDF networks of each
//! collection (`DIR/merl`, `DIR/nielsen2015`, `DIR/rgl-isotropic`) into the compact `.nbrdf`
//! files bundled in `crates/deepbrdf-data/assets/nbrdf`. The output is a pure function of the
//! JSON (sorted, no timestamps), so re-packing the same folder gives identical files.
use anyhow::Context;
use deepbrdf_data::bundled::Collection;
use deepbrdf_data::files::create_parent_and_write;
use deepbrdf_data::nbrdf::{pack, read_json_folder};
use deepbrdf_data::Progress;
use sha2::{Digest, Sha256};
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder holding one sub-folder of JSON networks per collection (merl, nielsen2015,
    /// rgl-isotropic).
    #[arg(long, value_name = "DIR")]
    pub from: PathBuf,
    /// Folder to write `<collection>.nbrdf` into.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    progress.start(Collection::ALL.len() as u64, "packing networks");
    for collection in Collection::ALL {
        let dir = args.from.join(collection.source_folder());
        let networks =
            read_json_folder(&dir).with_context(|| format!("reading the {collection} networks"))?;
        let bytes = pack(&networks)?;
        let path = args.out.join(collection.pack_file_name());
        let unchanged = std::fs::read(&path).is_ok_and(|old| old == bytes);
        if !unchanged {
            create_parent_and_write(&path, &bytes)?;
        }
        println!(
            "{:12} {:4} networks {:8} bytes  sha256 {}  {}{}",
            collection.name(),
            networks.len(),
            bytes.len(),
            hex::encode(Sha256::digest(&bytes)),
            path.display(),
            if unchanged { " (unchanged)" } else { "" }
        );
        progress.advance(1);
    }
    progress.finish();
    Ok(())
}
