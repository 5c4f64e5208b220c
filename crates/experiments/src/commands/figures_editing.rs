//! `experiments figures-editing [--model DIR] [--out results/editing] [--every N]`: the
//! editing figures of §5.1 as JPEG strips and the measured edit suite
//! (`deepbrdf_eval::editing::measures`), in-sample (the
//! model and the regressors saw every material).
//!
//! - Fig. 10: red-metallic-paint to red-fabric in 9 steps, DeepBRDF latent vs IPCA coefficients
//!   vs a linear blend of the tables.
//! - Fig. 12: the diffuse albedo of gray-plastic set to several colours.
//! - Fig. 13: the roughness of red-plastic swept from x1/4 to x4.
//! - Fig. 14: the same sweep of specular-yellow-phenolic, DeepBRDF vs IPCA.
//! - The suite, on every N-th material: diffuse albedo x0.5 and a hue change (its channels
//!   rotated), specular albedo x0.5, roughness x0.5 and x2, and the identity edit, for DeepBRDF
//!   and IPCA (at the model's k), paper and residual edits and the residual edit carried onto
//!   the table (transfer), and the edits without a network, analytic
//!   (`deepbrdf_eval::editing::analytic`), stretch (`deepbrdf_eval::editing::stretch`) and, with
//!   `--separation-data DIR`, stretch on Sun et al. 2018's split (`deepbrdf_eval::separation`): the
//!   attributes re-estimated on each
//!   decoded table against the requested ones (target error, change ratio, drift of the
//!   untouched attributes), the identity edit's image RelAE against the original, the
//!   plausibility of every decoded table; the specular lobe read off each decoded table against
//!   the original's (`deepbrdf_eval::editing::lobe`: diffuse floor, peak and half width ratios, a
//!   dark hole at the highlight, and the bar each edit is held to); and the monotonicity of the
//!   re-estimated roughness along each Fig. 13/14 sweep.
//!
//! Writes `results.md` (the tables), `suite.csv` (every material and edit) and the figures.
use crate::args::data::DataArgs;
use crate::editing::{self, EditMode, EditorArg, ModelCodec, Space, DEFAULT_MODE};
use anyhow::Context;
use deepbrdf_data::dataset::{DataSource, Dataset};
use deepbrdf_data::{MerlTable, Progress};
use deepbrdf_eval::attributes::{Attributes, FitConfig};
use deepbrdf_eval::baseline::BaselineCodec;
use deepbrdf_eval::editing::interpolation::{self, InterpolationPath as Path3};
use deepbrdf_eval::editing::suite::{self, report, Suite, SuiteInput, SuiteRepresentation as Rep};
use deepbrdf_eval::editing::{is_monotone, ColourEdit, Edit, ScalarEdit};
use deepbrdf_eval::figures::{figure_caption, strip};
use deepbrdf_eval::metrics::{ImageRelae, ImageRelaeConfig};
use deepbrdf_eval::separation::{self, SeparatedBasis};
use deepbrdf_model::DeepBrdf;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub editor: EditorArg,
    /// Output folder.
    #[arg(long, value_name = "DIR", default_value = "results/editing")]
    pub out: PathBuf,
    /// Run the suite on every N-th material of the dataset (1: all).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..))]
    pub every: u32,
    /// Epochs of the IPCA regressor when none is saved [default: the library's].
    #[arg(long)]
    pub epochs: Option<usize>,
    /// The figures' renders.
    #[command(flatten)]
    pub figure: crate::args::figure::FigureArg,
    /// Skip the figures (suite only).
    #[arg(long)]
    pub no_figures: bool,
    /// Add the stretch edit on Sun et al. 2018's diffuse-specular split to the suite, the
    /// separation fitted to the MERL .binary files of DIR (the training folder when the suite's
    /// materials are held out).
    #[arg(long, value_name = "DIR")]
    pub separation_data: Option<PathBuf>,
    #[command(flatten)]
    pub data: DataArgs,
}

/// The roughness scales of the Fig. 13/14 sweeps.
const SWEEP: [f64; 7] = [0.25, 0.397, 0.63, 1.0, 1.587, 2.52, 4.0];

/// A sweep of `edits` on one material for one representation and mode: its tables. The
/// table is encoded only for a mode that edits its latent ([`EditMode::needs_latent`]).
fn sweep(
    rep: &Rep,
    table: &MerlTable,
    original: &Attributes,
    edits: &[Edit],
    mode: EditMode,
) -> anyhow::Result<Vec<MerlTable>> {
    let latent = match mode.needs_latent() {
        true => rep.space.codec.encode(table)?,
        false => Vec::new(),
    };
    edits.iter().map(|e| Ok(rep.space.edit(table, &latent, original, e, mode)?.table)).collect()
}

/// What the figures are drawn from.
struct Figures<'a> {
    set: &'a Dataset,
    attrs: &'a [Attributes],
    fit: FitConfig,
    figure: ImageRelaeConfig,
    out: &'a Path,
    model: &'a DeepBrdf,
    ipca: &'a BaselineCodec,
    deep: &'a Rep<'a>,
    ipca_rep: &'a Rep<'a>,
    progress: &'a dyn Progress,
}

impl Figures<'_> {
    /// The index of material `name` in the set.
    fn index(&self, name: &str) -> anyhow::Result<usize> {
        self.set
            .names
            .iter()
            .position(|n| n == name)
            .with_context(|| format!("{name} is not in {}", self.set.label))
    }

    /// Figs. 10, 12, 13 and 14 and their sections of `md`; returns the table of re-estimated
    /// roughness along the sweeps of Figs. 13 and 14.
    fn draw(&self, md: &mut String) -> anyhow::Result<String> {
        self.fig10(md)?;
        self.fig12(md)?;
        self.roughness_sweeps(md)
    }

    /// Fig. 10: red-metallic-paint to red-fabric in 9 steps, with its section of `md`.
    fn fig10(&self, md: &mut String) -> anyhow::Result<()> {
        let (a, b) = (self.index("red-metallic-paint")?, self.index("red-fabric")?);
        let paths = interpolation::paths(
            self.model,
            Some(self.ipca),
            &self.set.tables[a],
            &self.set.tables[b],
            9,
            self.progress,
        )?;
        let refs: Vec<&[MerlTable]> = paths.iter().map(|p| p.tables.as_slice()).collect();
        let (sheet, noise) = strip(
            &refs,
            &|row, i| format!("{} t={:.3}", paths[row].name, i as f64 / 8.0),
            &self.figure,
        )?;
        sheet.write_figure(&self.out.join("fig10_interpolation.jpg"))?;
        let _ = write!(
            md,
            "## Fig. 10: red-metallic-paint to red-fabric, 9 steps\n\n![Fig. 10](fig10_interpolation.jpg)\n\n{}\n\nImage RelAE between consecutive steps (128 px sphere, sun and sky, 16 spp):\n\n",
            figure_caption(&self.figure, noise)
        );
        *md += &interpolation::summary(&paths)?;
        Ok(())
    }

    /// Fig. 12: the diffuse albedo of gray-plastic set to several colours, with its section.
    fn fig12(&self, md: &mut String) -> anyhow::Result<()> {
        let g = self.index("gray-plastic")?;
        let colours: [(&str, [f64; 3]); 6] = [
            ("red", [0.5, 0.05, 0.05]),
            ("orange", [0.5, 0.25, 0.03]),
            ("green", [0.08, 0.4, 0.08]),
            ("blue", [0.05, 0.1, 0.5]),
            ("white", [0.7, 0.7, 0.7]),
            ("black", [0.01, 0.01, 0.01]),
        ];
        let edits: Vec<Edit> = colours
            .iter()
            .map(|(_, c)| Edit { diffuse: Some(ColourEdit::Set(*c)), ..Edit::default() })
            .collect();
        let reference = ImageRelae::new(&self.set.tables[g], &ImageRelaeConfig::default())?;
        let mut rows = Vec::new();
        for mode in [EditMode::Paper, EditMode::Residual, DEFAULT_MODE] {
            let mut tables = vec![self.set.tables[g].clone()];
            tables.extend(sweep(self.deep, &self.set.tables[g], &self.attrs[g], &edits, mode)?);
            let images = interpolation::render_all(&reference, &tables)?;
            let name = match mode.needs_network() {
                true => format!("DeepBRDF {}", mode.name()),
                false => mode.name().to_string(),
            };
            rows.push(Path3 { name, tables, images });
        }
        let refs: Vec<&[MerlTable]> = rows.iter().map(|p| p.tables.as_slice()).collect();
        let captions = |row: usize, i: usize| match i {
            0 => "original".into(),
            _ => format!("{} {}", rows[row].name.trim_start_matches("DeepBRDF "), colours[i - 1].0),
        };
        let (sheet, noise) = strip(&refs, &captions, &self.figure)?;
        sheet.write_figure(&self.out.join("fig12_diffuse.jpg"))?;
        let _ = write!(
            md,
            "\n## Fig. 12: diffuse albedo of gray-plastic\n\n![Fig. 12](fig12_diffuse.jpg)\n\n{}\n\nRows: the paper's edit, the residual edit (DeepBRDF), the default edit without a network ({default}); first column the measurement. Requested vs re-estimated diffuse albedo:\n\n| edit | requested | paper: achieved | residual: achieved | {default}: achieved |\n| --- | --- | --- | --- | --- |\n",
            figure_caption(&self.figure, noise),
            default = DEFAULT_MODE.name()
        );
        for (i, (name, c)) in colours.iter().enumerate() {
            let got: Vec<String> = rows
                .iter()
                .map(|r| {
                    let a = editing::attributes_of(&r.tables[i + 1], name, &self.fit)?;
                    anyhow::Ok(format!(
                        "{:.3} {:.3} {:.3}",
                        a.diffuse[0], a.diffuse[1], a.diffuse[2]
                    ))
                })
                .collect::<anyhow::Result<_>>()?;
            let _ = writeln!(
                md,
                "| {name} | {:.3} {:.3} {:.3} | {} | {} | {} |",
                c[0], c[1], c[2], got[0], got[1], got[2]
            );
        }
        Ok(())
    }

    /// Figs. 13 and 14: roughness sweeps, their sections in `md` and the table of re-estimated
    /// roughness along each sweep, returned.
    fn roughness_sweeps(&self, md: &mut String) -> anyhow::Result<String> {
        let mut sweeps_md = String::new();
        let sweep_edits: Vec<Edit> = SWEEP
            .iter()
            .map(|s| Edit { roughness: Some(ScalarEdit::Scale(*s)), ..Edit::default() })
            .collect();
        sweeps_md += "\n## Roughness sweeps (Figs. 13, 14): re-estimated roughness along x1/4 ... x4\n\n| material | representation | edit | requested | re-estimated | monotone |\n| --- | --- | --- | --- | --- | --- |\n";
        for (fig, material, methods) in [
            ("fig13_roughness", "red-plastic", vec![self.deep]),
            ("fig14_roughness", "specular-yellow-phenolic", vec![self.deep, self.ipca_rep]),
        ] {
            let m = self.index(material)?;
            let a = &self.attrs[m];
            let usable: Vec<(f64, Edit)> = SWEEP
                .iter()
                .copied()
                .zip(sweep_edits.iter().copied())
                .filter(|(_, e)| e.apply(a).is_ok())
                .collect();
            let edits: Vec<Edit> = usable.iter().map(|(_, e)| *e).collect();
            let reference = ImageRelae::new(&self.set.tables[m], &ImageRelaeConfig::default())?;
            let mut rows = Vec::new();
            // Each representation's paper and residual edits, then the default edit (no
            // network) once.
            let runs = methods
                .iter()
                .flat_map(|rep| [(*rep, EditMode::Paper), (*rep, EditMode::Residual)])
                .chain([(self.deep, DEFAULT_MODE)]);
            for (rep, mode) in runs {
                let rep_name = if mode.needs_network() { rep.name } else { "-" };
                let tables = sweep(rep, &self.set.tables[m], a, &edits, mode)?;
                let got: Vec<f64> = tables
                    .iter()
                    .map(|t| Ok(editing::attributes_of(t, material, &self.fit)?.roughness))
                    .collect::<anyhow::Result<_>>()?;
                let requested: Vec<String> =
                    usable.iter().map(|(s, _)| format!("{:.3}", a.roughness * s)).collect();
                let shown: Vec<String> = got.iter().map(|r| format!("{r:.3}")).collect();
                let _ = writeln!(
                    sweeps_md,
                    "| {material} | {} | {} | {} | {} | {} |",
                    rep_name,
                    mode.name(),
                    requested.join(" "),
                    shown.join(" "),
                    if is_monotone(&got, true, 0.0) { "yes" } else { "no" }
                );
                let images = interpolation::render_all(&reference, &tables)?;
                let name = match mode.needs_network() {
                    true => format!("{} {}", rep.name, mode.name()),
                    false => mode.name().to_string(),
                };
                rows.push(Path3 { name, tables, images });
            }
            let refs: Vec<&[MerlTable]> = rows.iter().map(|p| p.tables.as_slice()).collect();
            let captions = |row: usize, i: usize| format!("{} x{:.2}", rows[row].name, usable[i].0);
            let (sheet, noise) = strip(&refs, &captions, &self.figure)?;
            sheet.write_figure(&self.out.join(format!("{fig}.jpg")))?;
            let _ = write!(
                md,
                "\n## {}: roughness of {material}\n\n![{fig}]({fig}.jpg)\n\n{}\n\nRows: {}; columns: roughness x{}.\n",
                if fig.starts_with("fig13") { "Fig. 13" } else { "Fig. 14" },
                figure_caption(&self.figure, noise),
                rows.iter().map(|r| r.name.as_str()).collect::<Vec<_>>().join(", "),
                usable.iter().map(|(s, _)| format!("{s:.2}")).collect::<Vec<_>>().join(", x")
            );
        }
        Ok(sweeps_md)
    }
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let started = Instant::now();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let figure = args.figure.config()?;
    let device = crate::args::device::device()?;
    let (model_dir, model, deep_regressor) = args.editor.load(&device)?;
    let k = model.k();
    let set = args.data.load(progress)?;
    let fit = FitConfig::default();
    let attrs = editing::attributes_of_all(&set, &fit, progress)?;
    // IPCA at the same k, with its regressor (saved by `train-regressor --ipca`, else trained
    // here on the same materials).
    let reg_dir = editing::regressor_dir(&model_dir, args.editor.regressor.as_deref());
    let scratch = args.out.join("ipca-regressor");
    let (ipca, ipca_regressor) =
        editing::ipca_editor(&reg_dir, &set, &attrs, k, args.epochs, &scratch, progress, &device)?;
    let deep_codec = ModelCodec(&model);
    let reps = [
        Rep { name: "DeepBRDF", space: Space { codec: &deep_codec, regressor: &deep_regressor } },
        Rep { name: "IPCA", space: Space { codec: &ipca, regressor: &ipca_regressor } },
    ];
    let mut md = header(&model, &set, &crate::args::model::shown(&reg_dir));
    let mut sweeps_md = String::new();
    if !args.no_figures {
        let figures = Figures {
            set: &set,
            attrs: &attrs,
            fit,
            figure,
            out: &args.out,
            model: &model,
            ipca: &ipca,
            deep: &reps[0],
            ipca_rep: &reps[1],
            progress,
        };
        sweeps_md = figures.draw(&mut md)?;
    }
    let separation = match &args.separation_data {
        Some(dir) => Some(fit_separation(dir, &args.data, progress)?),
        None => None,
    };
    let input = SuiteInput {
        names: &set.names,
        tables: &set.tables,
        attributes: &attrs,
        every: args.every as usize,
        representations: &reps,
        separation: separation.as_ref(),
    };
    let suite = suite::run(&input, progress)?;
    deepbrdf_data::files::write_atomic(
        &args.out.join("suite.csv"),
        report::csv(&suite.rows).as_bytes(),
    )?;
    md += &suite_sections(&suite, args.every, set.len());
    md += &sweeps_md;
    let _ = write!(md, "\nWhole command {:.0} s.\n", started.elapsed().as_secs_f64());
    deepbrdf_data::files::write_atomic(&args.out.join("results.md"), md.as_bytes())?;
    println!("{md}");
    println!("wrote {}", args.out.display());
    Ok(())
}

/// The results' title and provenance: the model, the materials and whether it saw them.
fn header(model: &DeepBrdf, set: &Dataset, regressors: &str) -> String {
    let seen = set.names.iter().filter(|n| model.provenance().trained_on(n)).count();
    let scope = if seen == set.len() {
        "in-sample: the autoencoder was trained on every one of them".to_string()
    } else if seen == 0 {
        "held out: none of them was in the autoencoder's training set".to_string()
    } else {
        format!("{seen} of them were in the autoencoder's training set")
    };
    format!(
        "# Editing (§5.1): figures and measured suite\n\nWritten by `experiments figures-editing` (model {}, k = {}, {} materials of {}; {scope}; the regressors are those of `{regressors}`, or trained here on these materials when missing).\n\n",
        model.id(),
        model.k(),
        set.len(),
        set.label,
    )
}

/// Sun et al. 2018's split fitted to the MERL files of `dir`.
fn fit_separation(
    dir: &Path,
    data: &DataArgs,
    progress: &dyn Progress,
) -> anyhow::Result<SeparatedBasis> {
    let source = DataSource::Folder(dir.to_path_buf());
    let train = Dataset::load(&source, &data.cache(), progress)
        .with_context(|| format!("loading the separation's data {}", source.label()))?;
    Ok(separation::fit_split(&train.tables.iter().collect::<Vec<_>>(), progress)?)
}

/// The suite's sections of the results: the re-estimated attributes and the lobe tables.
fn suite_sections(suite: &Suite, every: u32, of: usize) -> String {
    let mut md = format!(
        "\n## Edit suite ({} materials: every {every}-th of {of}; attributes re-estimated with the fit on a quarter of its cells)\n\nMedians over the materials (means in `suite.csv`' rows): target error `|achieved - requested| / |requested|` of the edited attribute, change ratio (achieved change over requested change, 1 = as asked), relative drift of the untouched attributes, share of materials whose edit is within 10% of the target with less than 10% drift of every other attribute; identity edit: image RelAE against the measurement; plausible: no negative value and directional albedo <= 1 at 0-85 degrees.\n\n| representation | edit | mode | target error | change ratio | diffuse drift | specular drift | roughness drift | within 10% / drift < 10% | identity image RelAE | plausible |\n| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n{}",
        suite.materials,
        report::outcome_summary(&suite.rows)
    );
    let _ = write!(
        md,
        "\n### The specular lobe as a person sees it\n\nRead off each decoded table against the measurement: the luminance over theta_h (theta_d < 15 deg, all phi_d), the diffuse floor (its median for theta_h >= 45 deg), the lobe above it, its peak and half width at half maximum; a dark hole is the lobe at theta_h ~ 0 below 60% of its maximum within 15 deg where the measurement's was not. Per edit in `suite.csv` (`floor_ratio`, `peak_ratio`, `hwhm_ratio`, `dark_hole`, `lobe_bar`, `meets_bar`, `lobe_pass`). Dark holes are counted over every edit, identity included.\n\n{}",
        report::lobe_summary(&suite.rows)
    );
    for skipped in &suite.lobe_skipped {
        let _ = writeln!(md, "\nLobe not measured: {skipped}.");
    }
    md
}
