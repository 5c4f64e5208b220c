//! `experiments figures-quality [--model DIR] [--collection merl | --data DIR] [--out
//! results/fig5-6]`: Figs. 5 and 6 of Hu et al. (2020).
//!
//! - Fig. 5 (§3.3): every material of the dataset encoded by the model, the latents projected
//!   onto their first two principal components ([`LatentPlane`]) and drawn as a scatter plot,
//!   each dot in the colour of the material's render, a spread of them shown as a small render
//!   with the name ([`draw_scatter`]).
//! - Fig. 6 (§4): a few materials rendered as measured, as DeepBRDF reconstructs them (at the
//!   model's k) and as PCA and IPCA do at several k, both fitted here on the dataset; the image
//!   RelAE of each reconstruction under its tile ([`ImageRelae`] on the preview sphere under sun
//!   and sky, at a size and sample count where the renderer's grain is not visible, Sobol
//!   points). The renderer's noise at those settings is measured beside it: the RelAE between
//!   two renders of each measurement with different seeds (an upper bound: a reconstruction is
//!   rendered with the measurement's seed and sampling, so most noise cancels in its RelAE).
//!
//! Like the paper's figures both are in-sample by default: the shipped model and PCA and IPCA
//! fitted on the whole dataset have seen every material shown. `--held-out` fits PCA and IPCA
//! without the Fig. 6 materials and refuses a model trained on any of them.
use crate::args::data::DataArgs;
use crate::args::model::ModelArg;
use crate::editing::ModelCodec;
use anyhow::{bail, Context};
use deepbrdf_data::files::write_atomic;
use deepbrdf_data::{MerlTable, Progress, Silent};
use deepbrdf_eval::baseline::{BaselineCodec, BaselineMethod};
use deepbrdf_eval::figures::{draw_scatter, LatentPlane, ScatterPlot, ScatterPoint};
use deepbrdf_eval::harness::{Codec, Method as _};
use deepbrdf_eval::metrics::{relae, ImageRelae};
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::sheet::{contact_sheet, SheetConfig, Tile};
use deepbrdf_render::{render, MerlBrdf, RenderSettings, Tonemap};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub model: ModelArg,
    #[command(flatten)]
    pub data: DataArgs,
    /// Fig. 6's materials, by name in the dataset (a diffuse, a plastic, a metal and a paint by
    /// default).
    #[arg(
        long,
        value_name = "NAME,...",
        value_delimiter = ',',
        default_value = "blue-fabric,red-specular-plastic,nickel,gold-metallic-paint"
    )]
    pub materials: Vec<String>,
    /// Fig. 6's numbers of PCA and IPCA components (each one adds two columns; `5,10,20,40` for
    /// a finer sweep, three by default to keep the committed figure small).
    #[arg(long = "k", value_name = "K,...", value_delimiter = ',', default_value = "5,10,40")]
    pub ks: Vec<usize>,
    /// Fig. 6's renders.
    #[command(flatten)]
    pub figure: crate::args::figure::FigureArg,
    /// Fig. 5: at most this many materials shown as a render with their name.
    #[arg(long, default_value_t = 24)]
    pub labels: usize,
    /// Fig. 6 held out: fit PCA and IPCA without its materials, and refuse a model trained on
    /// any of them.
    #[arg(long)]
    pub held_out: bool,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "results/fig5-6")]
    pub out: PathBuf,
}

/// Fig. 5's plot size and thumbnails: side in pixels and samples per pixel.
const FIG5_SIZE: (u32, u32) = (1400, 1000);
const THUMB_SIZE: u32 = 56;
const THUMB_SPP: u32 = 16;
/// Fig. 5's background (the thumbnails are composited over it).
const WHITE: [u8; 3] = [255, 255, 255];
/// Fig. 6's sheet of `columns` tiles: captions larger than the default, for 256-px tiles.
fn sheet_config(columns: u32) -> SheetConfig {
    SheetConfig { columns, caption_height: 22, font_px: 15, ..SheetConfig::default() }
}

/// One column of Fig. 6 after the measurement: a method at one k, the image RelAE of each
/// material and its tiles.
struct Column {
    method: String,
    k: usize,
    relae: Vec<f64>,
    tiles: Vec<Tile>,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let started = Instant::now();
    let mut ks = args.ks.clone();
    ks.sort_unstable();
    ks.dedup();
    if ks.is_empty() || ks[0] == 0 {
        bail!("--k must list at least one number of components, each at least 1");
    }
    if args.materials.is_empty() {
        bail!("--materials must name at least one material");
    }
    let device = crate::args::device::device()?;
    let model_dir = args.model.dir()?;
    let model = DeepBrdf::load(&model_dir, &device)
        .with_context(|| format!("loading the model {}", model_dir.display()))?;
    let set = args.data.load(progress)?;
    let n = set.len();
    let shown: Vec<usize> = args
        .materials
        .iter()
        .map(|m| {
            set.names.iter().position(|n| n == m).with_context(|| {
                format!("--materials: '{m}' is not in {} ({n} materials)", set.label)
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let fit_rows: Vec<&MerlTable> =
        (0..n).filter(|i| !(args.held_out && shown.contains(i))).map(|i| &set.tables[i]).collect();
    let k_max = ks[ks.len() - 1];
    if k_max + 1 > fit_rows.len() {
        bail!(
            "--k {k_max}: PCA of {} materials has at most {} components",
            fit_rows.len(),
            fit_rows.len().saturating_sub(1)
        );
    }
    let seen: Vec<&str> = shown
        .iter()
        .map(|&i| set.names[i].as_str())
        .filter(|m| model.provenance().trained_on(m))
        .collect();
    if args.held_out && !seen.is_empty() {
        bail!(
            "--held-out: the model {} was trained on {}; give --model with a model trained \
             without them",
            model_dir.display(),
            seen.join(", ")
        );
    }
    let config = args.figure.config()?;
    let settings = config.render;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let tonemap = Tonemap::default();
    let deep = ModelCodec(&model);
    let k = model.k();

    // Fig. 5: every material's latent, its thumbnail, the plane.
    progress.start(n as u64, "encoding");
    let mut latents = Vec::with_capacity(n);
    for table in &set.tables {
        latents.push(deep.encode(table)?);
        progress.advance(1);
    }
    progress.finish();
    let scene = config.scene.build()?;
    let thumb_settings = RenderSettings { size: THUMB_SIZE, spp: THUMB_SPP, ..settings };
    progress.start(n as u64, "thumbnails");
    let mut thumbs = Vec::with_capacity(n);
    for table in &set.tables {
        thumbs.push(render(&scene, &MerlBrdf::new(table), &thumb_settings, &Silent)?);
        progress.advance(1);
    }
    progress.finish();
    let plane = LatentPlane::fit(&latents).context("Fig. 5: projecting the latents")?;
    let percent = |f: f64| 100.0 * f;
    let points: Vec<ScatterPoint> = (0..n)
        .map(|i| ScatterPoint {
            x: plane.coords[i][0],
            y: plane.coords[i][1],
            colour: thumbs[i].object_mean().map_or([0; 3], |c| tonemap.srgb8(c)),
            name: set.names[i].clone(),
            thumbnail: thumbs[i].to_srgb8(&tonemap, WHITE),
        })
        .collect();
    let plot = ScatterPlot {
        title: format!(
            "Fig. 5: the {n} materials of {} in DeepBRDF's latent space (k = {k}), first two \
             principal components",
            set.label
        ),
        x_label: format!("latent PC 1 ({:.0}% of the variance)", percent(plane.explained[0])),
        y_label: format!("latent PC 2 ({:.0}% of the variance)", percent(plane.explained[1])),
        points,
        labels: args.labels,
        size: FIG5_SIZE,
    };
    let (fig5, labelled) = draw_scatter(&plot)?;
    fig5.write_png(&args.out.join("fig5.png"))?;
    let mut csv5 = String::from("material,pc1,pc2,labelled");
    for j in 0..k {
        write!(csv5, ",z{j}")?;
    }
    csv5.push('\n');
    for (i, (latent, [x, y])) in latents.iter().zip(&plane.coords).enumerate() {
        write!(csv5, "{},{x:.6},{y:.6},{}", set.names[i], labelled.contains(&i))?;
        for z in latent {
            write!(csv5, ",{z:.6}")?;
        }
        csv5.push('\n');
    }
    write_atomic(&args.out.join("fig5.csv"), csv5.as_bytes())?;

    // Fig. 6: the measurements and the renderer's noise.
    let columns = 2 + 2 * ks.len();
    progress.start((shown.len() * (columns + 1)) as u64, "rendering Fig. 6");
    let sheet = sheet_config(columns as u32);
    let srgb = |img: &deepbrdf_render::Image| img.to_srgb8(&tonemap, sheet.background);
    let mut measures = Vec::with_capacity(shown.len());
    let mut noise = Vec::with_capacity(shown.len());
    let mut originals = Vec::with_capacity(shown.len());
    for &i in &shown {
        let measure = ImageRelae::new(&set.tables[i], &config)?;
        progress.advance(1);
        noise.push(measure.noise(&set.tables[i])?);
        progress.advance(1);
        originals.push(Tile { image: srgb(measure.reference()), caption: set.names[i].clone() });
        measures.push(measure);
    }
    let column = |method: &str, codec: &dyn Codec| -> anyhow::Result<Column> {
        let mut c = Column { method: method.into(), k: codec.k(), relae: vec![], tiles: vec![] };
        for (s, &i) in shown.iter().enumerate() {
            let latent = match method {
                "DeepBRDF" => latents[i].clone(),
                _ => codec.encode(&set.tables[i])?,
            };
            let image = measures[s].render(&codec.decode(&latent)?)?;
            let e = relae(&image, measures[s].reference())?;
            c.relae.push(e);
            c.tiles.push(Tile {
                image: srgb(&image),
                caption: format!("{method} {}D: RelAE {e:.3}", codec.k()),
            });
            progress.advance(1);
        }
        Ok(c)
    };
    let mut cols = vec![column("DeepBRDF", &deep)?];
    for method in [BaselineMethod::pca(), BaselineMethod::ipca()] {
        let name = method.name();
        // The fit's own bar replaces the rendering bar's line for a moment.
        let basis = Arc::new(method.fit_basis(&fit_rows, k_max, &Silent)?);
        for codec in BaselineCodec::nested(&basis, &ks)? {
            cols.push(column(&name, &codec)?);
        }
    }
    progress.finish();
    let mut tiles = Vec::with_capacity(shown.len() * columns);
    for (s, original) in originals.into_iter().enumerate() {
        tiles.push(original);
        tiles.extend(cols.iter().map(|c| c.tiles[s].clone()));
    }
    contact_sheet(&tiles, &sheet)?.write_figure(&args.out.join("fig6.jpg"))?;

    let mut csv6 = String::from("material,render_noise");
    for c in &cols {
        write!(csv6, ",{}_{}", c.method.to_lowercase(), c.k)?;
    }
    csv6.push('\n');
    let mut table = String::from("| material | render noise |");
    for c in &cols {
        write!(table, " {} {}D |", c.method, c.k)?;
    }
    table += "\n| --- | ---: |";
    table += &" ---: |".repeat(cols.len());
    table.push('\n');
    for (s, &i) in shown.iter().enumerate() {
        write!(csv6, "{},{:.6}", set.names[i], noise[s])?;
        write!(table, "| {} | {:.4} |", set.names[i], noise[s])?;
        for c in &cols {
            write!(csv6, ",{:.6}", c.relae[s])?;
            write!(table, " {:.4} |", c.relae[s])?;
        }
        csv6.push('\n');
        table.push('\n');
    }
    write_atomic(&args.out.join("fig6.csv"), csv6.as_bytes())?;

    let model_scope = match seen.len() {
        0 => "the model was not trained on any of them".to_string(),
        s if s == shown.len() => format!(
            "the model was trained on all {} (its training data: {})",
            shown.len(),
            model.provenance().data_label
        ),
        s => format!("the model was trained on {s} of them ({})", seen.join(", ")),
    };
    let baseline_scope = if args.held_out {
        format!("PCA and IPCA fitted on the other {} materials of {}", fit_rows.len(), set.label)
    } else {
        format!(
            "PCA and IPCA fitted on all {n} materials of {}, the shown ones included",
            set.label
        )
    };
    let scope = if args.held_out { "held out" } else { "in-sample, as in the paper" };
    let max_noise = noise.iter().copied().fold(0.0, f64::max);
    let (x_share, y_share) = (percent(plane.explained[0]), percent(plane.explained[1]));
    let md = format!(
        "# Figs. 5 and 6\n\nWritten by `experiments figures-quality` with model {id} (k = {k}, \
         trained on {data}) on {label} ({n} materials), {secs:.0} s.\n\n\
         ## Fig. 5: the latent space\n\n![Fig. 5](fig5.png)\n\n\
         Every material of {label} encoded by the model (its refined latent, eq. 2), the {n} \
         latents of {k} values projected onto their first two principal components (PCA of the \
         latents, eq. 5): {x_share:.1}% and {y_share:.1}% of their variance. Each dot is in the \
         mean colour of the material's render on the preview sphere; {shown_labels} of them \
         (chosen to spread over the plane) are shown as that render ({THUMB_SIZE} px, \
         {THUMB_SPP} spp) with their name. The paper's Fig. 5 is a diagram of the same idea: the \
         autoencoder maps the measured BRDFs onto a low-dimensional manifold. In-sample: the \
         model's training data is {data}. Coordinates and latents: `fig5.csv`.\n\n\
         ## Fig. 6: reconstruction quality\n\n![Fig. 6](fig6.jpg)\n\n\
         Rows: {materials}; columns: the measurement, DeepBRDF at k = {k}, PCA (log of the \
         reflectance) and IPCA (Nielsen et al.'s log-relative mapping) at k = {ks}. Under each \
         reconstruction its image RelAE against the measurement's render (the preview sphere \
         under sun and sky, {size} px, {spp} spp, Sobol points, seed {seed}; each \
         reconstruction rendered with the measurement's seed and sampling). {scope_cap}: \
         {model_scope}; {baseline_scope}.\n\n\
         Render noise: the image RelAE between two renders of the measurement with seeds \
         {seed} and {seed2}, at most {max_noise:.4}; each reconstruction's RelAE shares its \
         render's random numbers with the measurement's, so its noise is below that.\n\n{table}",
        id = model.id(),
        data = model.provenance().data_label,
        label = set.label,
        secs = started.elapsed().as_secs_f64(),
        shown_labels = labelled.len(),
        materials = args.materials.join(", "),
        ks = ks.iter().map(usize::to_string).collect::<Vec<_>>().join(", "),
        size = settings.size,
        spp = settings.spp,
        seed = settings.seed,
        seed2 = config.next_seed().render.seed,
        scope_cap = capitalise(scope),
    );
    write_atomic(&args.out.join("summary.md"), md.as_bytes())?;
    print!("{md}");
    eprintln!("wrote {}/fig5.png, fig5.csv, fig6.jpg, fig6.csv, summary.md", args.out.display());
    Ok(())
}

/// `s` with its first letter upper-case.
fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next().map_or_else(String::new, |f| f.to_uppercase().chain(c).collect())
}
