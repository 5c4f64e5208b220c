//! `figures-recovery`'s outputs: `per_image.csv`, `summary.md` with its per-material charts,
//! and Figs. 16 and 17.
use super::measure::{Found, Row, Shown};
use super::{Args, METHODS};
use deepbrdf_eval::figures::{write_chart, LineChart, Series};
use deepbrdf_eval::stats::{finite_mean, finite_median};
use deepbrdf_model::recovery::RecoveryArtifact;
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::sheet::{contact_sheet, SheetConfig, Tile};
use deepbrdf_render::Srgb8Image;
use std::fmt::Write as _;
use std::path::Path;

/// Writes every output of the run (and prints the summary).
pub(super) fn write(
    args: &Args,
    found: &Found,
    model: &DeepBrdf,
    network: &RecoveryArtifact,
    analytic: &RecoveryArtifact,
) -> anyhow::Result<()> {
    let out = &args.out;
    deepbrdf_data::files::write_atomic(
        &out.join("per_image.csv"),
        per_image_csv(&found.rows)?.as_bytes(),
    )?;
    let md = summary(args, found, model, network, analytic)?;
    deepbrdf_data::files::write_atomic(&out.join("summary.md"), md.as_bytes())?;
    print!("{md}");
    figures(args, &found.shown, &found.planes)?;
    eprintln!(
        "wrote {}/summary.md, per_image.csv, per_material_*.svg, fig16.jpg, fig17.jpg",
        out.display()
    );
    Ok(())
}

/// Every image's RelAE and mapped MSE per method, as CSV.
fn per_image_csv(rows: &[Row]) -> anyhow::Result<String> {
    let mut csv = String::from("set,index,material,shape,nearest");
    for m in METHODS {
        write!(csv, ",relae_{m}")?;
    }
    for m in METHODS {
        write!(csv, ",mapped_mse_{m}")?;
    }
    csv.push('\n');
    for r in rows {
        write!(csv, "{},{},{},{},{}", r.set, r.index, r.material, r.shape, r.nearest)?;
        for v in r.relae.iter().chain(&r.mse) {
            write!(csv, ",{v:.6}")?;
        }
        csv.push('\n');
    }
    Ok(csv)
}

/// The summary: the networks, the settings, the table per test set and method, the
/// per-material charts (written beside it) and the figures' captions.
fn summary(
    args: &Args,
    found: &Found,
    model: &DeepBrdf,
    network: &RecoveryArtifact,
    analytic: &RecoveryArtifact,
) -> anyhow::Result<String> {
    let Found { rows, skipped, shown, planes } = found;
    let mut md = String::new();
    writeln!(md, "Single-image recovery (§5.2), written by `experiments figures-recovery` (see the README's Recovery section for the full command).")?;
    writeln!(md)?;
    writeln!(
        md,
        "DeepBRDF model {} (k = {}); recovery CNN {} ({} images, {} epochs); analytic CNN {}.",
        model.id(),
        model.k(),
        network.id(),
        network.provenance().images,
        network.provenance().epochs,
        analytic.id()
    )?;
    writeln!(md, "Novel-scene renders: {0}x{0} px, {1} spp. RelAE: image space, novel shape, view and sky; MSE: mapped space (eq. 1), the model's reference.", args.size, args.spp)?;
    for (set, n, of) in skipped.iter().filter(|s| s.1 > 0) {
        writeln!(md, "{set}: {n} of {of} images skipped as unusable (the checks `recover` applies to a photo: no object, no dark background, saturated).")?;
    }
    writeln!(md)?;
    writeln!(md, "| test set | images | materials | method | RelAE mean | RelAE median | mapped MSE mean | best RelAE on |")?;
    writeln!(md, "| --- | ---: | ---: | --- | ---: | ---: | ---: | ---: |")?;
    let mut sets: Vec<&str> = rows.iter().map(|r| r.set.as_str()).collect();
    sets.dedup();
    for set in &sets {
        let rs: Vec<&Row> = rows.iter().filter(|r| r.set == *set).collect();
        let mut materials: Vec<&str> = rs.iter().map(|r| r.material.as_str()).collect();
        materials.sort();
        materials.dedup();
        for (m, method) in METHODS.iter().enumerate() {
            let wins = rs.iter().filter(|r| (0..4).all(|o| r.relae[m] <= r.relae[o])).count();
            writeln!(
                md,
                "| {set} | {} | {} | {method} | {:.4} | {:.4} | {:.4} | {wins} |",
                rs.len(),
                materials.len(),
                finite_mean(rs.iter().map(|r| r.relae[m])),
                finite_median(rs.iter().map(|r| r.relae[m])),
                finite_mean(rs.iter().map(|r| r.mse[m])),
            )?;
        }
    }
    for set in &sets {
        writeln!(md)?;
        writeln!(md, "![{set}, per material](per_material_{set}.svg)")?;
        per_material_chart(rows, set, &args.out.join(format!("per_material_{set}")))?;
    }
    if !shown.is_empty() || !planes.is_empty() {
        let noise = shown.iter().chain(planes).map(|s| s.noise).fold(0.0, f64::max);
        writeln!(md)?;
        writeln!(
            md,
            "Fig. 16 (`fig16.jpg`: held-out inputs as the network sees them, enlarged; the truth \
             and DeepBRDF's recovery rendered in the novel scene) and Fig. 17 (`fig17.jpg`: \
             held-out planes, the truth, DeepBRDF and the analytic baseline re-rendered in the \
             input's own scene): {0} px, {1} spp, Sobol points, seed 0; the RelAE under a tile \
             is at these settings. Render noise (the truth rendered with seeds 0 and 1): at \
             most {noise:.4}.",
            args.figure_size, args.figure_spp
        )?;
        writeln!(md)?;
        writeln!(md, "![Fig. 16](fig16.jpg)")?;
        writeln!(md)?;
        writeln!(md, "![Fig. 17](fig17.jpg)")?;
    }
    Ok(md)
}

/// Fig. 16 (inputs, truth, DeepBRDF) and Fig. 17 (planes: input, truth, DeepBRDF, analytic).
fn figures(args: &Args, shown: &[Shown], planes: &[Shown]) -> anyhow::Result<()> {
    let short = |m: &str| m.rsplit('/').next().unwrap_or(m).to_string();
    let up = |img: &Srgb8Image| img.upscaled((args.figure_size / img.width.max(1)).max(1));
    let sheet_config = |columns: usize| SheetConfig {
        columns: columns as u32,
        caption_height: 22,
        font_px: 15,
        ..Default::default()
    };
    if !shown.is_empty() {
        let mut tiles = Vec::new();
        for row in 0..3 {
            for s in shown {
                let (image, caption) = match row {
                    0 => (up(&s.input), short(&s.material)),
                    1 => (s.truth.clone(), "ground truth".to_string()),
                    _ => (s.recovered[0].clone(), format!("DeepBRDF: RelAE {:.3}", s.relae[0])),
                };
                tiles.push(Tile { image, caption });
            }
        }
        contact_sheet(&tiles, &sheet_config(shown.len()))?
            .write_figure(&args.out.join("fig16.jpg"))?;
    }
    if !planes.is_empty() {
        let mut tiles = Vec::new();
        for row in 0..4 {
            for s in planes {
                let (image, caption) = match row {
                    0 => (up(&s.input), format!("{} (input)", short(&s.material))),
                    1 => (s.truth.clone(), "ground truth".to_string()),
                    2 => (s.recovered[0].clone(), format!("DeepBRDF: RelAE {:.3}", s.relae[0])),
                    _ => (s.recovered[1].clone(), format!("analytic: RelAE {:.3}", s.relae[1])),
                };
                tiles.push(Tile { image, caption });
            }
        }
        contact_sheet(&tiles, &sheet_config(planes.len()))?
            .write_figure(&args.out.join("fig17.jpg"))?;
    }
    Ok(())
}

/// The novel-scene RelAE of each method per material of test set `set` (the mean over the
/// material's images), materials sorted by the methods' geometric mean, as `<stem>.svg`.
fn per_material_chart(rows: &[Row], set: &str, stem: &Path) -> anyhow::Result<()> {
    let rs: Vec<&Row> = rows.iter().filter(|r| r.set == set).collect();
    let mut materials: Vec<&str> = rs.iter().map(|r| r.material.as_str()).collect();
    materials.sort();
    materials.dedup();
    let value = |material: &str, m: usize| {
        finite_mean(rs.iter().filter(|r| r.material == material).map(|r| r.relae[m]))
    };
    let key =
        |material: &str| (0..METHODS.len()).map(|m| value(material, m).max(1e-9).ln()).sum::<f64>();
    materials.sort_by(|a, b| key(a).total_cmp(&key(b)));
    let series = METHODS
        .iter()
        .enumerate()
        .map(|(m, method)| Series {
            label: method.to_string(),
            points: materials.iter().enumerate().map(|(x, n)| (x as f64, value(n, m))).collect(),
        })
        .collect();
    let chart = LineChart {
        title: format!("recovery, {set}: image RelAE per material, novel scenes"),
        x_label: "material".into(),
        y_label: "image RelAE".into(),
        log_y: true,
        series,
        categories: Some(
            materials.iter().map(|m| m.rsplit('/').next().unwrap_or(m).to_string()).collect(),
        ),
        rotate_categories: true,
        legend_left: true,
        size: ((300 + 14 * materials.len() as u32).clamp(900, 2600), 520),
    };
    write_chart(&chart, stem)?;
    Ok(())
}
