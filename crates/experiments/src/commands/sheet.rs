//! `experiments sheet`: every material of a dataset rendered on the same scene, in one contact
//! sheet with the material names as captions.
use crate::args::data::DataArgs;
use crate::args::scene::SceneArgs;
use deepbrdf_data::Progress;
use deepbrdf_data::Silent;
use deepbrdf_render::{contact_sheet, render, MerlBrdf, SheetConfig, Tile};
use std::path::PathBuf;
use std::time::Instant;

/// Background of the tiles and the sheet (8-bit sRGB).
const BACKGROUND: [u8; 3] = [24, 24, 24];

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub data: DataArgs,
    /// Output PNG.
    #[arg(short, long, value_name = "PNG")]
    pub output: PathBuf,
    /// Tiles per row [default: about square].
    #[arg(long, default_value_t = 0)]
    pub columns: u32,
    #[command(flatten)]
    pub scene: SceneArgs,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let setup = args.scene.setup(128)?;
    let dataset = args.data.load(progress)?;
    let start = Instant::now();
    progress.start(dataset.tables.len() as u64, "sheet");
    let mut tiles = Vec::with_capacity(dataset.tables.len());
    for (name, table) in dataset.names.iter().zip(&dataset.tables) {
        let image = render(&setup.scene, &MerlBrdf::new(table), &setup.settings, &Silent)?;
        let image = image.to_srgb8(&setup.tonemap, BACKGROUND);
        tiles.push(Tile { image, caption: name.clone() });
        progress.advance(1);
    }
    progress.finish();
    let sheet = contact_sheet(
        &tiles,
        &SheetConfig { columns: args.columns, background: BACKGROUND, ..Default::default() },
    )?;
    sheet.write_png(&args.output)?;
    println!(
        "{} materials of {} ({}x{} each, {} on a {}, {} spp) rendered in {:.1} s -> {}",
        tiles.len(),
        dataset.label,
        setup.settings.size,
        setup.settings.size,
        setup.config.light,
        setup.config.shape,
        setup.settings.spp,
        start.elapsed().as_secs_f64(),
        args.output.display()
    );
    Ok(())
}
