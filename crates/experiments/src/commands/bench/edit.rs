//! `experiments bench edit [--model DIR] [MATERIAL] [edit options]`: the time of one edit of
//! §5.1 (target: <= 0.5 s on 2 cores), split into the regressor (eq. 7, twice for the residual
//! edit), the decode (eq. 3) and a 128-pixel preview render (sphere, sun and sky, 16 spp); the
//! attribute fit and the encode of the material, done once when it is picked, are timed apart.
//! The edits of the table itself (no network: stretch, and parts with its fit of the material's
//! parts, done once per material) are timed too. Without an edit option the edit is roughness
//! x0.5.
use crate::args::data::CacheArg;
use crate::args::edit::EditArgs;
use crate::editing::{self, EditMode, EditorArg, ModelCodec, Space, DEFAULT_LATENT_MODE};
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::{Progress, Silent};
use deepbrdf_eval::attributes::FitConfig;
use deepbrdf_eval::editing::parts::{fit_parts, parts_edit, PartsConfig};
use deepbrdf_eval::editing::{stretch_edit, Edit, ScalarEdit};
use deepbrdf_eval::harness::Codec;
use deepbrdf_eval::metrics::ImageRelaeConfig;
use deepbrdf_eval::stats::finite_median;
use deepbrdf_render::{render, MerlBrdf};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub editor: EditorArg,
    /// The material to edit.
    #[arg(default_value = "red-plastic")]
    pub material: String,
    #[command(flatten)]
    pub edit: EditArgs,
    #[arg(long, value_parser = editing::mode_parser(&EditMode::LATENT))]
    pub mode: Option<EditMode>,
    /// Timed edits (after one warm-up).
    #[arg(long, default_value_t = 5)]
    pub reps: usize,
    #[command(flatten)]
    pub cache: CacheArg,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let device = crate::args::device::device()?;
    let t = Instant::now();
    let (_, model, regressor) = args.editor.load(&device)?;
    let load = t.elapsed().as_secs_f64();
    let (name, table) = load_material(&args.material, &args.cache.cache())
        .with_context(|| format!("loading material '{}'", args.material))?;
    let t = Instant::now();
    let original = editing::attributes_of(&table, &name, &FitConfig::default())?;
    let fit = t.elapsed().as_secs_f64();
    let codec = ModelCodec(&model);
    let t = Instant::now();
    let latent = codec.encode(&table)?;
    let encode = t.elapsed().as_secs_f64();
    let mut edit = args.edit.edit()?;
    if edit == Edit::default() {
        edit.roughness = Some(ScalarEdit::Scale(0.5));
    }
    let mode = args.mode.unwrap_or(DEFAULT_LATENT_MODE);
    let space = Space { codec: &codec, regressor: &regressor };
    let preview = ImageRelaeConfig::default();
    let scene = preview.scene.build()?;
    let (mut reg, mut dec, mut ren, mut all) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for rep in 0..=args.reps.max(1) {
        let t0 = Instant::now();
        let requested = edit.apply(&original)?;
        let z = space.edited_latent(&latent, &original, &requested, mode)?;
        let t1 = Instant::now();
        let edited = codec.decode(&z)?;
        let t2 = Instant::now();
        let _image = render(&scene, &MerlBrdf::new(&edited), &preview.render, &Silent)?;
        let t3 = Instant::now();
        if rep > 0 {
            reg.push((t1 - t0).as_secs_f64());
            dec.push((t2 - t1).as_secs_f64());
            ren.push((t3 - t2).as_secs_f64());
            all.push((t3 - t0).as_secs_f64());
        }
    }
    println!(
        "{name}, {} edit, model {} (k = {}), {} threads; medians of {} edits",
        mode.name(),
        model.id(),
        model.k(),
        rayon::current_num_threads(),
        all.len()
    );
    println!(
        "one edit: {:.3} s (target <= 0.5 s): regressor {:.5} s, decode {:.3} s, 128 px preview {:.3} s",
        finite_median(all),
        finite_median(reg),
        finite_median(dec),
        finite_median(ren)
    );
    // The table edits, without a network.
    let t = Instant::now();
    let parts = fit_parts(&table, &PartsConfig::default())?.parts;
    let parts_fit = t.elapsed().as_secs_f64();
    let requested = edit.apply(&original)?;
    let (mut stretch, mut by_parts) = (Vec::new(), Vec::new());
    for rep in 0..=args.reps.max(1) {
        let t0 = Instant::now();
        let _ = stretch_edit(&table, &original, &requested)?;
        let t1 = Instant::now();
        let _ = parts_edit(&table, &parts, &original, &requested)?;
        if rep > 0 {
            stretch.push((t1 - t0).as_secs_f64());
            by_parts.push(t1.elapsed().as_secs_f64());
        }
    }
    println!(
        "table edits (no network, no preview): stretch {:.3} s, parts {:.3} s",
        finite_median(stretch),
        finite_median(by_parts)
    );
    println!("once per material: attribute fit {fit:.3} s, parts fit {parts_fit:.3} s, encode {encode:.3} s; loading model and regressor {load:.2} s");
    Ok(())
}
