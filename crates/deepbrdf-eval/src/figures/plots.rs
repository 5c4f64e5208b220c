//! Line charts with [`plotters`], written as SVG in the compact form of [`super::compact`]
//! (a chart of 100 materials is a tenth of its PNG, and results folders are committed). Text is laid out with the DejaVu
//! Sans font embedded in the binary (the `dejavu` crate, through plotters' `ab_glyph`
//! feature), so a chart is the same with no system fonts installed.

use crate::error::{EvalError, Result};
use deepbrdf_data::files::write_atomic;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontTransform;
use std::path::{Path, PathBuf};

/// One line of a chart.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    /// (x, y) points; non-finite or (on a log axis) non-positive y values are skipped.
    pub points: Vec<(f64, f64)>,
}

/// A line chart.
#[derive(Clone, Debug)]
pub struct LineChart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_y: bool,
    pub series: Vec<Series>,
    /// Category names for integer x positions 0, 1, 2, ... (materials, or k values); `None` for
    /// a numeric x axis.
    pub categories: Option<Vec<String>>,
    /// Draw category names vertically in a small font (many long names, e.g. materials).
    pub rotate_categories: bool,
    /// Put the legend in the upper left corner instead of the upper right.
    pub legend_left: bool,
    /// Pixel size (width, height).
    pub size: (u32, u32),
}

/// Writes `chart` to `<stem>.svg` (through a temp file and a rename).
pub fn write_chart(chart: &LineChart, stem: &Path) -> Result<()> {
    write_panels(std::slice::from_ref(chart), stem)
}

/// Writes `charts` stacked top to bottom in one figure (width: the widest; height: the sum) to
/// `<stem>.svg` (through a temp file and a rename).
pub fn write_panels(charts: &[LineChart], stem: &Path) -> Result<()> {
    deepbrdf_render::sheet::register_font()?;
    if charts.is_empty() {
        return Err(EvalError::Invalid(format!("{}: no chart to draw", stem.display())));
    }
    let w = charts.iter().map(|c| c.size.0).max().unwrap_or(1);
    let h: u32 = charts.iter().map(|c| c.size.1).sum();
    if u64::from(w) * u64::from(h) > 64_000_000 {
        return Err(EvalError::Invalid(format!("{}: figure of {w} x {h} pixels", stem.display())));
    }
    let svg_path = with_ext(stem, "svg");
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        draw_stacked(&root, charts)
            .map_err(|e| EvalError::Invalid(format!("{}: {e}", svg_path.display())))?;
        root.present().map_err(|e| EvalError::Invalid(format!("{}: {e}", svg_path.display())))?;
    }
    Ok(write_atomic(&svg_path, super::compact::compact_svg(&svg).as_bytes())?)
}

/// Writes `charts` stacked top to bottom in one figure to `<stem>.png` (through a temp file
/// and a rename): for a figure looked at in a browser or an issue rather than printed.
pub fn write_panels_png(charts: &[LineChart], stem: &Path) -> Result<()> {
    deepbrdf_render::sheet::register_font()?;
    let png_path = with_ext(stem, "png");
    if charts.is_empty() {
        return Err(EvalError::Invalid(format!("{}: no chart to draw", png_path.display())));
    }
    let w = charts.iter().map(|c| c.size.0).max().unwrap_or(1);
    let h: u32 = charts.iter().map(|c| c.size.1).sum();
    if u64::from(w) * u64::from(h) > 64_000_000 {
        return Err(EvalError::Invalid(format!(
            "{}: figure of {w} x {h} pixels",
            png_path.display()
        )));
    }
    let mut pixels = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        draw_stacked(&root, charts)
            .map_err(|e| EvalError::Invalid(format!("{}: {e}", png_path.display())))?;
        root.present().map_err(|e| EvalError::Invalid(format!("{}: {e}", png_path.display())))?;
    }
    let image = image::RgbImage::from_raw(w, h, pixels)
        .ok_or_else(|| EvalError::Invalid(format!("{}: pixel buffer size", png_path.display())))?;
    let mut bytes = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
        .map_err(|e| EvalError::Invalid(format!("{}: {e}", png_path.display())))?;
    Ok(write_atomic(&png_path, &bytes)?)
}

/// Draws each chart in its own horizontal band of `root`, top to bottom.
fn draw_stacked<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    charts: &[LineChart],
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let mut rest = root.clone();
    for (i, chart) in charts.iter().enumerate() {
        if i + 1 == charts.len() {
            draw(&rest, chart)?;
        } else {
            let (top, bottom) = rest.split_vertically(chart.size.1);
            draw(&top, chart)?;
            rest = bottom;
        }
    }
    Ok(())
}

fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Distinct, print-friendly line colours.
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// A y tick label: on a log axis only mantissas 1, 2 and 5 are labelled ("2e-3"), so labels
/// never crowd; on a linear axis three significant digits.
fn y_label(y: f64, log: bool) -> String {
    if !log {
        return format!("{y:.3}");
    }
    if !(y.is_finite() && y > 0.0) {
        return String::new();
    }
    let exponent = y.log10().floor();
    let mantissa = y / 10f64.powf(exponent);
    for m in [1.0, 2.0, 5.0, 10.0] {
        if (mantissa - m).abs() < 1e-6 * m {
            let e = if m == 10.0 { exponent + 1.0 } else { exponent };
            let m = if m == 10.0 { 1.0 } else { m };
            return format!("{m}e{e}");
        }
    }
    String::new()
}

type DrawResult<DB> =
    std::result::Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, chart: &LineChart) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let keep = |y: f64| y.is_finite() && (!chart.log_y || y > 0.0);
    let points = || {
        chart.series.iter().flat_map(|s| s.points.iter()).filter(|p| keep(p.1) && p.0.is_finite())
    };
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in points() {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 1.0, 10.0);
    }
    if chart.categories.is_some() {
        x0 -= 0.5;
        x1 += 0.5;
    } else {
        let pad = if x1 > x0 { (x1 - x0) * 0.04 } else { 0.5 };
        x0 -= pad;
        x1 += pad;
    }
    if chart.log_y {
        y0 /= 1.5;
        y1 *= 1.5;
    } else {
        let pad = ((y1 - y0) * 0.05).max(1e-12);
        y0 -= pad;
        y1 += pad;
    }
    let bottom = if chart.rotate_categories { 190 } else { 60 };
    let mut builder = ChartBuilder::on(root);
    builder
        .caption(&chart.title, ("sans-serif", 26))
        .margin(16)
        .x_label_area_size(bottom)
        .y_label_area_size(100);

    let categories = chart.categories.clone();
    let x_fmt = move |x: &f64| match &categories {
        Some(names) => {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
                names[i as usize].clone()
            } else {
                String::new()
            }
        }
        // At most three decimals, trailing zeros dropped: ticks such as 0.1 + 0.2 read 0.3.
        None => {
            let s = format!("{x:.3}");
            let s =
                if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.') } else { &s };
            if s == "-0" {
                "0".to_string()
            } else {
                s.to_string()
            }
        }
    };
    let x_labels = chart.categories.as_ref().map(|c| c.len()).unwrap_or(12);
    let x_style = if chart.rotate_categories {
        TextStyle::from(("sans-serif", 12).into_font()).transform(FontTransform::Rotate90)
    } else {
        TextStyle::from(("sans-serif", 16).into_font())
    };

    macro_rules! finish {
        ($ctx:expr) => {{
            let mut ctx = $ctx;
            ctx.configure_mesh()
                .x_desc(&chart.x_label)
                .y_desc(&chart.y_label)
                .axis_desc_style(("sans-serif", 18))
                .x_labels(x_labels)
                .x_label_formatter(&x_fmt)
                .x_label_style(x_style.clone())
                .y_label_style(("sans-serif", 15))
                .y_labels(if chart.log_y { 30 } else { 10 })
                .light_line_style(TRANSPARENT)
                .bold_line_style(BLACK.mix(0.12))
                .y_label_formatter(&|y: &f64| y_label(*y, chart.log_y))
                .draw()?;
            for (i, s) in chart.series.iter().enumerate() {
                let colour = COLOURS[i % COLOURS.len()];
                let pts: Vec<(f64, f64)> =
                    s.points.iter().copied().filter(|p| keep(p.1) && p.0.is_finite()).collect();
                ctx.draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
                    .label(s.label.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
                    });
                ctx.draw_series(pts.into_iter().map(|p| Circle::new(p, 3, colour.filled())))?;
            }
            ctx.configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 16))
                .position(if chart.legend_left {
                    SeriesLabelPosition::UpperLeft
                } else {
                    SeriesLabelPosition::UpperRight
                })
                .draw()?;
        }};
    }
    if chart.log_y {
        finish!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?);
    } else {
        finish!(builder.build_cartesian_2d(x0..x1, y0..y1)?);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_axis_labels_only_one_two_five() {
        assert_eq!(y_label(0.01, true), "1e-2");
        assert_eq!(y_label(2e-3, true), "2e-3");
        assert_eq!(y_label(5e4, true), "5e4");
        assert_eq!(y_label(3e-3, true), "");
        assert_eq!(y_label(9.9999999999e-3, true), "1e-2");
        assert_eq!(y_label(0.0, true), "");
        assert_eq!(y_label(0.25, false), "0.250");
    }

    use crate::figures::compact_svg;

    #[test]
    fn writes_an_svg_with_its_text_and_lines() {
        let dir = tempfile::tempdir().unwrap();
        let chart = LineChart {
            title: "error vs k".into(),
            x_label: "k".into(),
            y_label: "MSE".into(),
            log_y: true,
            series: vec![
                Series { label: "PCA".into(), points: vec![(5.0, 0.3), (10.0, 0.1), (20.0, 0.05)] },
                Series {
                    label: "IPCA".into(),
                    points: vec![(5.0, 0.03), (10.0, 0.01), (20.0, 0.0)],
                },
            ],
            categories: None,
            rotate_categories: false,
            legend_left: false,
            size: (640, 420),
        };
        let stem = dir.path().join("chart");
        write_chart(&chart, &stem).unwrap();
        let svg = std::fs::read_to_string(dir.path().join("chart.svg")).unwrap();
        assert!(svg.contains("IPCA") && svg.contains("error vs k"));
        assert!(svg.contains(r#"width="640""#) && svg.contains(r#"height="420""#), "{svg}");
        // Both series are drawn as lines (IPCA's 0.0 is skipped on the log axis).
        for colour in ["#1F77B4", "#D62728"] {
            let style = format!("{{fill:none;stroke:{colour};stroke-width:2}}");
            assert!(svg.contains(&style), "{colour}: {svg}");
        }
        assert!(svg.matches("<path class=").count() >= 2, "{svg}");
        // Written compact: compacting again changes nothing.
        assert_eq!(compact_svg(&svg), svg);
        assert!(!dir.path().join("chart.png").exists());
    }
}
