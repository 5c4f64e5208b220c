//! A scatter plot whose points are materials: every point a dot in the material's colour, and
//! as many as fit without overlapping shown as a small render with the name under it (Fig. 5,
//! the latent plane). Drawn with plotters into an 8-bit image (the renders are pixels, so the
//! figure is a PNG, not one of the SVG charts of [`super::plots`]), text in the embedded DejaVu
//! Sans.

use crate::error::{EvalError, Result};
use deepbrdf_render::Srgb8Image;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// One point.
#[derive(Clone, Debug)]
pub struct ScatterPoint {
    pub x: f64,
    pub y: f64,
    /// The dot's colour (8-bit sRGB).
    pub colour: [u8; 3],
    pub name: String,
    /// The render shown for a labelled point (all of one size).
    pub thumbnail: Srgb8Image,
}

/// A scatter plot.
#[derive(Clone, Debug)]
pub struct ScatterPlot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub points: Vec<ScatterPoint>,
    /// At most this many points are labelled (thumbnail and name).
    pub labels: usize,
    /// Pixel size (width, height).
    pub size: (u32, u32),
}

/// Font size of the names under the thumbnails, pixels.
const NAME_PX: u32 = 12;
/// Radius of a dot, pixels.
const DOT_RADIUS: i32 = 5;
/// Background of the plot (white) and the thumbnails' frame.
const FRAME: [u8; 3] = [90, 90, 90];

/// A labelled point's box in pixels: left, top, right, bottom (exclusive).
#[derive(Clone, Copy, Debug, PartialEq)]
struct LabelBox {
    left: i32,
    top: i32,
    right: i32,
    bottom: i32,
}

impl LabelBox {
    fn overlaps(&self, o: &LabelBox) -> bool {
        self.left < o.right && o.left < self.right && self.top < o.bottom && o.top < self.bottom
    }

    fn inside(&self, area: &LabelBox) -> bool {
        self.left >= area.left
            && self.top >= area.top
            && self.right <= area.right
            && self.bottom <= area.bottom
    }
}

/// Draws `plot`; returns the image and, in order of choice, the indices of the labelled points.
///
/// Labels are chosen greedily, farthest point first (from the centroid, then from the points
/// already labelled, in pixels), so they spread over the plane; a point is skipped when its
/// thumbnail and name would overlap a label already placed or leave the plotting area.
pub fn draw_scatter(plot: &ScatterPlot) -> Result<(Srgb8Image, Vec<usize>)> {
    deepbrdf_render::sheet::register_font()?;
    let (w, h) = plot.size;
    if plot.points.is_empty() {
        return Err(EvalError::Invalid(format!("scatter plot '{}': no points", plot.title)));
    }
    if !(200..=8000).contains(&w) || !(200..=8000).contains(&h) {
        return Err(EvalError::Invalid(format!(
            "scatter plot of {w} x {h} pixels: each side must be in 200..=8000"
        )));
    }
    if let Some(p) = plot.points.iter().find(|p| !(p.x.is_finite() && p.y.is_finite())) {
        return Err(EvalError::Invalid(format!("point '{}' is at ({}, {})", p.name, p.x, p.y)));
    }
    let thumb = &plot.points[0].thumbnail;
    if let Some(p) = plot
        .points
        .iter()
        .find(|p| (p.thumbnail.width, p.thumbnail.height) != (thumb.width, thumb.height))
    {
        return Err(EvalError::Invalid(format!(
            "thumbnail of '{}' is {}x{}, the first is {}x{}",
            p.name, p.thumbnail.width, p.thumbnail.height, thumb.width, thumb.height
        )));
    }
    let mut image = Srgb8Image::filled(w, h, [255, 255, 255]);
    let draw_err = |e: String| EvalError::Invalid(format!("drawing '{}': {e}", plot.title));

    // Pass 1: axes and dots; where each point lands and the label boxes.
    let (pixels, area, boxes) = {
        let root = BitMapBackend::with_buffer(&mut image.data, (w, h)).into_drawing_area();
        let placed = draw_axes_and_dots(&root, plot).map_err(|e| draw_err(e.to_string()))?;
        let name_style = TextStyle::from(("sans-serif", f64::from(NAME_PX)).into_font());
        let boxes: Vec<LabelBox> = plot
            .points
            .iter()
            .zip(&placed.0)
            .map(|(p, &(x, y))| {
                let text_w =
                    root.estimate_text_size(&p.name, &name_style).map(|s| s.0 as i32).unwrap_or(0);
                let half = (thumb.width as i32).max(text_w) / 2 + 1;
                let th = thumb.height as i32;
                LabelBox {
                    left: x - half,
                    top: y - th / 2 - 1,
                    right: x + half,
                    bottom: y + th / 2 + NAME_PX as i32 + 4,
                }
            })
            .collect();
        root.present().map_err(|e| draw_err(e.to_string()))?;
        (placed.0, placed.1, boxes)
    };
    let chosen = choose_labels(&pixels, &boxes, &area, plot.labels);

    // Pass 2: the thumbnails (pixels copied in), then their frames and names on top.
    let (tw, th) = (thumb.width as i32, thumb.height as i32);
    for &i in &chosen {
        let (x, y) = pixels[i];
        image.blit(
            &plot.points[i].thumbnail,
            (x - tw / 2).max(0) as u32,
            (y - th / 2).max(0) as u32,
        );
    }
    {
        let root = BitMapBackend::with_buffer(&mut image.data, (w, h)).into_drawing_area();
        let frame = RGBColor(FRAME[0], FRAME[1], FRAME[2]);
        let name_style = TextStyle::from(("sans-serif", f64::from(NAME_PX)).into_font())
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top));
        for &i in &chosen {
            let (x, y) = pixels[i];
            let (x0, y0) = (x - tw / 2, y - th / 2);
            root.draw(&Rectangle::new([(x0 - 1, y0 - 1), (x0 + tw, y0 + th)], frame))
                .map_err(|e| draw_err(e.to_string()))?;
            // The name on a light band, legible over the dots it may cross.
            let name = &plot.points[i].name;
            let (nw, nh) = root.estimate_text_size(name, &name_style).unwrap_or((0, NAME_PX));
            let (nw, nh) = (nw as i32, nh as i32);
            let band = [(x - nw / 2 - 2, y0 + th + 1), (x + nw / 2 + 2, y0 + th + 3 + nh)];
            root.draw(&Rectangle::new(band, WHITE.mix(0.85).filled()))
                .map_err(|e| draw_err(e.to_string()))?;
            root.draw_text(name, &name_style, (x, y0 + th + 2))
                .map_err(|e| draw_err(e.to_string()))?;
        }
        root.present().map_err(|e| draw_err(e.to_string()))?;
    }
    Ok((image, chosen))
}

/// The greedy farthest-first choice of labels ([`draw_scatter`]).
fn choose_labels(
    pixels: &[(i32, i32)],
    boxes: &[LabelBox],
    area: &LabelBox,
    labels: usize,
) -> Vec<usize> {
    let n = pixels.len();
    let (cx, cy) = (
        pixels.iter().map(|p| f64::from(p.0)).sum::<f64>() / n as f64,
        pixels.iter().map(|p| f64::from(p.1)).sum::<f64>() / n as f64,
    );
    let dist2 = |p: (i32, i32), q: (f64, f64)| {
        (f64::from(p.0) - q.0).powi(2) + (f64::from(p.1) - q.1).powi(2)
    };
    // Distance of each point to the nearest of the centroid (at first) and the chosen points.
    let mut nearest: Vec<f64> = pixels.iter().map(|&p| dist2(p, (cx, cy))).collect();
    let mut open: Vec<bool> = boxes.iter().map(|b| b.inside(area)).collect();
    let mut chosen: Vec<usize> = Vec::new();
    while chosen.len() < labels {
        // The open point farthest from everything chosen; ties to the lower index.
        let Some(best) = (0..n)
            .filter(|&i| open[i])
            .max_by(|&a, &b| nearest[a].total_cmp(&nearest[b]).then(b.cmp(&a)))
        else {
            break;
        };
        open[best] = false;
        if chosen.iter().any(|&c| boxes[c].overlaps(&boxes[best])) {
            continue;
        }
        chosen.push(best);
        let q = (f64::from(pixels[best].0), f64::from(pixels[best].1));
        for (i, d) in nearest.iter_mut().enumerate() {
            *d = d.min(dist2(pixels[i], q));
        }
    }
    chosen
}

type Placed = (Vec<(i32, i32)>, LabelBox);

/// Draws the title, axes and dots; returns each point's pixel and the plotting area.
fn draw_axes_and_dots<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &ScatterPlot,
) -> std::result::Result<Placed, DrawingAreaErrorKind<DB::ErrorType>> {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in &plot.points {
        x0 = x0.min(p.x);
        x1 = x1.max(p.x);
        y0 = y0.min(p.y);
        y1 = y1.max(p.y);
    }
    // Margins so that a label on an outermost point stays inside the plotting area: `need`
    // pixels of the (estimated) plotting area's `side` pixels is a padding of
    // `r / (1 - 2 r)` of the range, `r = need / side`.
    let thumb = &plot.points[0].thumbnail;
    let pad = |range: f64, need: u32, side: u32| {
        let r = (f64::from(need) / f64::from(side.max(1))).min(0.3);
        (range * r / (1.0 - 2.0 * r)).max(1e-9)
    };
    let (w, h) = plot.size;
    let px = pad(x1 - x0, thumb.width / 2 + 50, w.saturating_sub(102));
    let py = pad(y1 - y0, thumb.height / 2 + NAME_PX + 8, h.saturating_sub(112));
    let mut chart = ChartBuilder::on(root)
        .caption(&plot.title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d((x0 - px)..(x1 + px), (y0 - py)..(y1 + py))?;
    chart
        .configure_mesh()
        .x_desc(&plot.x_label)
        .y_desc(&plot.y_label)
        .axis_desc_style(("sans-serif", 17))
        .label_style(("sans-serif", 14))
        .light_line_style(TRANSPARENT)
        .bold_line_style(BLACK.mix(0.1))
        .x_label_formatter(&|v: &f64| tick(*v, x1 - x0))
        .y_label_formatter(&|v: &f64| tick(*v, y1 - y0))
        .draw()?;
    chart.draw_series(plot.points.iter().map(|p| {
        let c = RGBColor(p.colour[0], p.colour[1], p.colour[2]);
        EmptyElement::at((p.x, p.y))
            + Circle::new((0, 0), DOT_RADIUS, c.filled())
            + Circle::new((0, 0), DOT_RADIUS, BLACK.mix(0.6).stroke_width(1))
    }))?;
    let pixels = plot.points.iter().map(|p| chart.backend_coord(&(p.x, p.y))).collect();
    let (xr, yr) =
        (chart.plotting_area().get_pixel_range().0, chart.plotting_area().get_pixel_range().1);
    let area = LabelBox { left: xr.start, top: yr.start, right: xr.end, bottom: yr.end };
    Ok((pixels, area))
}

/// A tick label with as many decimals as an axis spanning `range` needs (none from 10 up).
fn tick(v: f64, range: f64) -> String {
    let decimals = (1.0 - range.abs().max(1e-12).log10().floor()).clamp(0.0, 6.0) as usize;
    format!("{v:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(i: usize, x: f64, y: f64) -> ScatterPoint {
        ScatterPoint {
            x,
            y,
            colour: [200, 20, 20],
            name: format!("m{i}"),
            thumbnail: Srgb8Image::filled(20, 20, [0, 0, 250]),
        }
    }

    #[test]
    fn labels_spread_without_overlap_and_thumbnails_land_on_their_points() {
        // Nine points: a tight cluster of six near the origin and three far apart. Labels are
        // the far ones first; the cluster gets at most one, since its labels would overlap.
        let mut points: Vec<ScatterPoint> =
            (0..6).map(|i| point(i, 0.01 * i as f64, 0.01 * i as f64)).collect();
        points.push(point(6, 10.0, 0.0));
        points.push(point(7, 0.0, 10.0));
        points.push(point(8, 10.0, 10.0));
        let plot = ScatterPlot {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            points,
            labels: 9,
            size: (400, 400),
        };
        let (image, chosen) = draw_scatter(&plot).unwrap();
        assert_eq!((image.width, image.height), (400, 400));
        assert!(chosen.contains(&6) && chosen.contains(&7) && chosen.contains(&8), "{chosen:?}");
        assert_eq!(chosen.iter().filter(|&&i| i < 6).count(), 1, "{chosen:?}");
        // A thumbnail's blue pixels are in the image; white background elsewhere.
        let blue = image.data.chunks(3).filter(|p| p == &[0, 0, 250]).count();
        assert!(blue >= 4 * 18 * 18, "{blue}");
        assert_eq!(&image.data[0..3], &[255, 255, 255]);
    }

    #[test]
    fn ticks_have_the_decimals_their_range_needs() {
        assert_eq!(tick(1500.0, 3500.0), "1500");
        assert_eq!(tick(0.5, 3.0), "0.5");
        assert_eq!(tick(0.25, 0.8), "0.25");
    }

    #[test]
    fn bad_input_is_refused() {
        let mut plot = ScatterPlot {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            points: vec![],
            labels: 1,
            size: (400, 400),
        };
        assert!(draw_scatter(&plot).is_err());
        plot.points = vec![point(0, 0.0, f64::NAN)];
        assert!(draw_scatter(&plot).is_err());
        plot.points = vec![point(0, 0.0, 0.0), point(1, 1.0, 1.0)];
        plot.points[1].thumbnail = Srgb8Image::filled(3, 3, [0; 3]);
        assert!(draw_scatter(&plot).is_err());
        plot.points.pop();
        plot.size = (10, 400);
        assert!(draw_scatter(&plot).is_err());
    }
}
