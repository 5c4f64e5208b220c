//! `experiments edit [--model DIR] MATERIAL [--diffuse R,G,B | --diffuse-scale X] [--specular
//! R,G,B | --specular-scale X] [--roughness X | --roughness-scale X]
//! [--mode paper|residual|nearest|transfer|analytic|stretch|parts] -o edited.binary
//! [--render edited.png]`:
//! edits a material's diffuse albedo, specular albedo or roughness (§5.1) through the model's
//! regressor (eq. 7) and decoder (eq. 3), or without a network (analytic, stretch, parts), writes
//! the edited MERL table, and prints the attributes asked for and those re-estimated on the
//! result.
use crate::args::data::CacheArg;
use crate::args::edit::EditArgs;
use crate::args::scene::SceneArgs;
use crate::editing::{self, EditMode, EditorArg, DEFAULT_MODE};
use anyhow::{bail, Context};
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::merl::write_merl;
use deepbrdf_data::Progress;
use deepbrdf_eval::attributes::{Attributes, FitConfig};
use deepbrdf_eval::editing::edit_material;
use deepbrdf_render::{render, MerlBrdf};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub editor: EditorArg,
    /// A MERL .binary file or a bundled material.
    pub material: String,
    #[command(flatten)]
    pub edit: EditArgs,
    /// paper: Y' = Phi(alpha'); residual: Y' = Y + Phi(alpha') - Phi(alpha); nearest: the
    /// latent nearest Y whose attributes, as a linear latent-to-attribute predictor reads them,
    /// change by alpha' - alpha; transfer: the residual edit's change carried onto the table itself; analytic: the table's fitted
    /// Lambertian + GGX model swapped for the edited one, no network; stretch: the table's own
    /// highlight stretched to the new roughness and the albedos edited as analytic, no network;
    /// parts: the table split into a diffuse floor, up to two lobes, a retro-reflective ridge
    /// and a sheen, each lobe stretched by its own roughness, the floor and the lobes scaled by
    /// the albedo edits, no network [default: parts].
    #[arg(long, value_parser = editing::mode_parser(&EditMode::ALL))]
    pub mode: Option<EditMode>,
    /// Output MERL .binary file.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Also render the edited material to this PNG (with the scene options).
    #[arg(long, value_name = "PNG")]
    pub render: Option<PathBuf>,
    /// Replace existing output files.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// `diffuse 0.123 0.456 0.789, specular ..., roughness ...`.
pub fn describe(a: &Attributes) -> String {
    let (d, s) = (a.diffuse, a.specular);
    format!(
        "diffuse {:.4} {:.4} {:.4}, specular {:.4} {:.4} {:.4}, roughness {:.4}",
        d[0], d[1], d[2], s[0], s[1], s[2], a.roughness
    )
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let edit = args.edit.edit()?;
    let mode = args.mode.unwrap_or(DEFAULT_MODE);
    if !mode.needs_network()
        && (args.editor.model.model.is_some() || args.editor.regressor.is_some())
    {
        bail!(
            "the {mode} edit uses no model or regressor: give --mode residual, paper or transfer \
             to edit through --model/--regressor"
        );
    }
    for path in std::iter::once(&args.output).chain(args.render.as_ref()) {
        if path.exists() && !args.force {
            bail!("{} exists; pass --force to replace it", path.display());
        }
    }
    let setup = args.render.as_ref().map(|_| args.scene.setup(256)).transpose()?;
    let started = Instant::now();
    let (name, table) = load_material(&args.material, &args.cache.cache())
        .with_context(|| format!("loading material '{}'", args.material))?;
    let fit = FitConfig::default();
    let original = editing::attributes_of(&table, &name, &fit)?;
    // Checked before the model loads: a bad value fails at once.
    edit.apply(&original).with_context(|| format!("editing {name}"))?;
    for note in edit.without_effect(&original) {
        eprintln!("warning: {name}: {note}");
    }
    let (edited, by) = match mode.needs_network() {
        false => (edit_material(&table, &original, &edit, mode, None)?, "no network".to_string()),
        true => {
            let device = crate::args::device::device()?;
            let model_dir = args.editor.model.dir()?;
            let (model, regressor) =
                editing::load_editor(&model_dir, args.editor.regressor.as_deref(), &device)?;
            let edited = edit_material(&table, &original, &edit, mode, Some((&model, &regressor)))?;
            (edited, format!("model {}", model.id()))
        }
    };
    write_merl(&edited.table, &args.output)?;
    let achieved = editing::attributes_of(&edited.table, "the edited table", &fit)?;
    println!("{name} ({by}, {} edit)", mode.name());
    println!("  original  {}", describe(&original));
    println!("  requested {}", describe(&edited.requested));
    println!("  achieved  {} (re-estimated on the result)", describe(&achieved));
    if let Some(parts) = &edited.parts {
        println!("  parts (fitted to the original):");
        for line in parts.describe().lines() {
            println!("    {line}");
        }
    }
    if let (Some(png), Some(setup)) = (&args.render, &setup) {
        let image = render(&setup.scene, &MerlBrdf::new(&edited.table), &setup.settings, progress)?;
        image.write_png(png, &setup.tonemap)?;
        println!("  rendered {} -> {}", setup.description(), png.display());
    }
    println!("wrote {} in {:.2} s", args.output.display(), started.elapsed().as_secs_f64());
    Ok(())
}
