//! Fig. 5 of Hu et al. (2020), §3.3: every material of a dataset encoded, the latents projected
//! onto their first two principal components ([`LatentPlane`]) and drawn as a scatter plot
//! ([`draw_scatter`]), each dot in the colour of the material's render and a spread of them
//! shown as a small render with the name.

use super::{draw_scatter, LatentPlane, ScatterPlot, ScatterPoint};
use crate::error::Result;
use crate::harness::Codec;
use crate::metrics::ImageRelaeConfig;
use deepbrdf_data::{MerlTable, Progress, Silent};
use deepbrdf_render::{render, MerlBrdf, RenderSettings, Srgb8Image, Tonemap};
use std::fmt::Write as _;

/// The plot's size in pixels.
pub const SIZE: (u32, u32) = (1400, 1000);
/// Side and samples per pixel of the thumbnails.
pub const THUMB_SIZE: u32 = 56;
pub const THUMB_SPP: u32 = 16;
/// The plot's background (the thumbnails are composited over it).
const WHITE: [u8; 3] = [255, 255, 255];

/// The materials of a map: names and tables in the same order.
pub struct LatentMapInput<'a> {
    pub label: &'a str,
    pub names: &'a [String],
    pub tables: &'a [MerlTable],
    /// The representation whose latents are mapped.
    pub codec: &'a dyn Codec,
    /// The scene and render settings of the thumbnails (their size and samples are
    /// [`THUMB_SIZE`] and [`THUMB_SPP`]).
    pub config: &'a ImageRelaeConfig,
    /// At most this many materials are shown as a render with their name.
    pub labels: usize,
}

/// The figure and what it shows.
pub struct LatentMap {
    /// Each material's latent, in the input's order.
    pub latents: Vec<Vec<f32>>,
    pub plane: LatentPlane,
    pub image: Srgb8Image,
    /// The materials shown as a render with their name.
    pub labelled: Vec<usize>,
}

impl LatentMap {
    /// Encodes every material, renders its thumbnail and draws the plot.
    pub fn draw(input: &LatentMapInput, progress: &dyn Progress) -> Result<Self> {
        let n = input.tables.len();
        progress.start(n as u64, "encoding");
        let mut latents = Vec::with_capacity(n);
        for table in input.tables {
            latents.push(input.codec.encode(table)?);
            progress.advance(1);
        }
        progress.finish();
        let scene = input.config.scene.build()?;
        let settings = RenderSettings { size: THUMB_SIZE, spp: THUMB_SPP, ..input.config.render };
        progress.start(n as u64, "thumbnails");
        let mut thumbs = Vec::with_capacity(n);
        for table in input.tables {
            thumbs.push(render(&scene, &MerlBrdf::new(table), &settings, &Silent)?);
            progress.advance(1);
        }
        progress.finish();
        let plane = LatentPlane::fit(&latents)?;
        let tonemap = Tonemap::default();
        let points: Vec<ScatterPoint> = (0..n)
            .map(|i| ScatterPoint {
                x: plane.coords[i][0],
                y: plane.coords[i][1],
                colour: thumbs[i].object_mean().map_or([0; 3], |c| tonemap.srgb8(c)),
                name: input.names[i].clone(),
                thumbnail: thumbs[i].to_srgb8(&tonemap, WHITE),
            })
            .collect();
        let percent = |j: usize| 100.0 * plane.explained[j];
        let plot = ScatterPlot {
            title: format!(
                "Fig. 5: the {n} materials of {} in DeepBRDF's latent space (k = {}), first two \
                 principal components",
                input.label,
                input.codec.k()
            ),
            x_label: format!("latent PC 1 ({:.0}% of the variance)", percent(0)),
            y_label: format!("latent PC 2 ({:.0}% of the variance)", percent(1)),
            points,
            labels: input.labels,
            size: SIZE,
        };
        let (image, labelled) = draw_scatter(&plot)?;
        Ok(Self { latents, plane, image, labelled })
    }

    /// `fig5.csv`: per material (named by `names`) its coordinates, whether it is labelled, and
    /// its latent.
    pub fn csv(&self, names: &[String]) -> String {
        let k = self.latents.first().map_or(0, Vec::len);
        let mut csv = String::from("material,pc1,pc2,labelled");
        for j in 0..k {
            let _ = write!(csv, ",z{j}");
        }
        csv.push('\n');
        for (i, (latent, [x, y])) in self.latents.iter().zip(&self.plane.coords).enumerate() {
            let _ = write!(csv, "{},{x:.6},{y:.6},{}", names[i], self.labelled.contains(&i));
            for z in latent {
                let _ = write!(csv, ",{z:.6}");
            }
            csv.push('\n');
        }
        csv
    }
}
