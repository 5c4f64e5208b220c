//! `experiments bench render-noise`: the renderer's efficiency at equal noise. For a
//! Lambertian, an analytic Lambertian + GGX plastic and measured materials, under sun and sky and
//! under a constant environment, prints seconds per image, the relative noise (standard deviation
//! over fully covered pixels of the difference of two seeds' renders, divided by sqrt(2) and by
//! the mean pixel value, pooled over several pairs of seeds) and the efficiency
//! `1 / (noise^2 x seconds)`, which does not depend on the sample count for an unbiased
//! estimator; also per CPU second (all threads together), which other load on a shared machine
//! disturbs less than wall time.
//!
//! Why several pairs: when a sharp lobe reflects the sun, a handful of sub-pixel highlight
//! pixels 300x brighter than the mean carry nearly all of the squared difference, and one pair's
//! noise is then an estimate from a few numbers (cg_sunflower under sun and sky, 64 spp, three
//! pairs of one renderer: 0.194, 0.085, 0.062). The `top` column says which share of the pooled
//! squared difference comes from the 0.1% of pixels with the largest differences.
use super::cpu_time::cpu_seconds;
use crate::args::data::CacheArg;
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::{Progress, Silent};
use deepbrdf_render::{
    render, Brdf, Image, Lambertian, LightSpec, MerlBrdf, RenderSettings, Sampler, Scene,
    SceneConfig, Sum,
};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Measured materials (bundled names or MERL .binary files), comma separated; the analytic
    /// Lambertian and plastic are always measured first.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "chrome,gold-metallic-paint,blue-fabric,rgl/satin_blue_rgb,rgl/cg_sunflower_rgb,rgl/paper_white_rgb"
    )]
    pub materials: Vec<String>,
    /// Lights (as `experiments render --light`), separated by semicolons.
    #[arg(long, value_delimiter = ';', default_value = "sun:40,30;const")]
    pub lights: Vec<String>,
    /// Image side in pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub size: u32,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: u32,
    /// Samplers to measure, comma separated (sobol, independent): each row once per sampler.
    #[arg(long, value_delimiter = ',', default_value = "independent,sobol")]
    pub samplers: Vec<Sampler>,
    /// Pairs of seeds whose differences the noise pools (seeds 1 and 2, 3 and 4, ...).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u64).range(1..=64))]
    pub pairs: u64,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// Relative noise of renders of one scene with different seeds, pooled over pairs: for each
/// pair, over the pixels fully covered in both, the variance of the per-pixel difference of the
/// channel means; the noise is the square root of the pairs' mean variance, divided by 2 (one
/// render's variance), over the mean pixel value of all pairs. Also returns the share of the
/// pooled squared deviation carried by the 0.1% of pixels (at least one per pair) with the
/// largest. `None` when a pair has fewer than two covered pixels or the images are black.
pub fn relative_noise(pairs: &[(Image, Image)]) -> Option<(f64, f64)> {
    let (mut var_sum, mut level_sum, mut top_sum, mut total_sum) = (0.0, 0.0, 0.0, 0.0);
    for (a, b) in pairs {
        let mut diffs = Vec::new();
        let mut sum = 0.0;
        for (((p, q), &ca), &cb) in
            a.pixels().iter().zip(b.pixels()).zip(a.coverage()).zip(b.coverage())
        {
            if ca < 1.0 || cb < 1.0 {
                continue;
            }
            let (mp, mq) = (mean3(p), mean3(q));
            diffs.push(mp - mq);
            sum += 0.5 * (mp + mq);
        }
        let n = diffs.len() as f64;
        if n < 2.0 {
            return None;
        }
        let mean_diff = diffs.iter().sum::<f64>() / n;
        let mut sq: Vec<f64> = diffs.iter().map(|d| (d - mean_diff).powi(2)).collect();
        sq.sort_unstable_by(|x, y| y.total_cmp(x));
        let total = sq.iter().sum::<f64>();
        top_sum += sq[..diffs.len().div_ceil(1000)].iter().sum::<f64>();
        total_sum += total;
        var_sum += total / (n - 1.0);
        level_sum += sum / n;
    }
    let m = pairs.len() as f64;
    if !(level_sum > 0.0) {
        return None;
    }
    let top = if total_sum > 0.0 { top_sum / total_sum } else { 0.0 };
    Some(((var_sum / m / 2.0).sqrt() / (level_sum / m), top))
}

fn mean3(p: &[f32; 3]) -> f64 {
    p.iter().map(|&v| f64::from(v)).sum::<f64>() / 3.0
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let threads = rayon::current_num_threads();
    println!(
        "bench render-noise: {0}x{0} sphere, {1} spp, {threads} threads (set RAYON_NUM_THREADS to change); noise = sd(seed 2i-1 - seed 2i) / sqrt(2) / mean over covered pixels, pooled over {2} pairs; top = share of it in the 0.1% largest pixels; efficiency = 1 / (noise^2 x s)",
        args.size, args.spp, args.pairs
    );
    let mut tables = Vec::new();
    for spec in &args.materials {
        let (name, table) = load_material(spec, &args.cache.cache())
            .with_context(|| format!("loading material '{spec}'"))?;
        tables.push((name, table));
    }
    let lambertian = Lambertian::new([0.5; 3]);
    let plastic = Sum::plastic([0.3, 0.2, 0.1], 0.1, [0.04; 3]);
    let mut brdfs: Vec<(String, Box<dyn Brdf + '_>, f64)> = vec![
        ("lambertian 0.5".into(), Box::new(lambertian), 0.0),
        ("plastic (lambertian + ggx 0.1)".into(), Box::new(plastic), 0.0),
    ];
    for (name, table) in &tables {
        let start = Instant::now();
        let brdf = MerlBrdf::new(table);
        let build = start.elapsed().as_secs_f64();
        brdfs.push((name.clone(), Box::new(brdf), build));
    }
    println!(
        "{:<34} {:<10} {:<11} {:>9} {:>9} {:>9} {:>6} {:>11} {:>11} {:>9}",
        "material",
        "light",
        "sampler",
        "s/image",
        "cpu s",
        "noise",
        "top",
        "efficiency",
        "eff. (cpu)",
        "build s"
    );
    for light in &args.lights {
        let spec: LightSpec = light.parse().with_context(|| format!("parsing light '{light}'"))?;
        let scene = SceneConfig { light: spec, ..Default::default() }.build()?;
        for (name, brdf, build) in &brdfs {
            for &sampler in &args.samplers {
                let (pairs, seconds, cpu) = render_pairs(&args, &scene, brdf.as_ref(), sampler)?;
                let (noise, top) = relative_noise(&pairs)
                    .with_context(|| format!("{name} under {light}: no covered, lit pixels"))?;
                let efficiency = |s: f64| format!("{:.1}", 1.0 / (noise * noise * s));
                println!(
                    "{name:<34} {light:<10} {:<11} {seconds:>9.3} {:>9} {noise:>9.4} {top:>6.3} {:>11} {:>11} {build:>9.3}",
                    sampler.to_string(),
                    cpu.map_or("n/a".into(), |c| format!("{c:.2}")),
                    efficiency(seconds),
                    cpu.map_or("n/a".into(), efficiency),
                );
            }
        }
    }
    Ok(())
}

/// `args.pairs` pairs of renders of `brdf` in `scene` with seeds 2i-1 and 2i, and the mean
/// wall and CPU seconds per render (CPU where the platform reports it).
fn render_pairs(
    args: &Args,
    scene: &Scene,
    brdf: &dyn Brdf,
    sampler: Sampler,
) -> anyhow::Result<(Vec<(Image, Image)>, f64, Option<f64>)> {
    let mut pairs = Vec::new();
    let mut seconds = 0.0;
    let renders = 2.0 * args.pairs as f64;
    let cpu_start = cpu_seconds();
    for pair in 0..args.pairs {
        let mut one = |seed| -> anyhow::Result<Image> {
            let settings =
                RenderSettings { size: args.size, spp: args.spp, seed, jitter: true, sampler };
            let start = Instant::now();
            let image = render(scene, brdf, &settings, &Silent)?;
            seconds += start.elapsed().as_secs_f64() / renders;
            Ok(image)
        };
        pairs.push((one(2 * pair + 1)?, one(2 * pair + 2)?));
    }
    let cpu = cpu_start.zip(cpu_seconds()).map(|(a, b)| (b - a) / renders);
    Ok((pairs, seconds, cpu))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_noise_of_known_images() {
        // Four covered pixels at level 2 (a) and 2 +- 0.2 alternating (b), plus uncovered and
        // partly covered pixels that must be ignored: the difference has sd 0.2 * sqrt(4/3)
        // (sample sd of +-0.2), so the noise is that / sqrt(2) / mean level (2, 2.1, 1.9 mean 2).
        let a = Image::from_pixels(3, 2, vec![[2.0; 3]; 6], vec![1.0, 1.0, 1.0, 1.0, 0.5, 0.0])
            .unwrap();
        let b = Image::from_pixels(
            3,
            2,
            vec![[2.2; 3], [1.8; 3], [2.2; 3], [1.8; 3], [9.0; 3], [9.0; 3]],
            vec![1.0; 6],
        )
        .unwrap();
        let want = 0.2 * (4.0f64 / 3.0).sqrt() / 2f64.sqrt() / 2.0;
        let (got, top) = relative_noise(&[(a.clone(), b.clone())]).unwrap();
        assert!((got - want).abs() < 1e-6, "{got} vs {want}");
        // Each of the four pixels carries a quarter; the top 0.1% is one pixel.
        assert!((top - 0.25).abs() < 1e-6, "{top}");
        assert_eq!(relative_noise(&[(a.clone(), a.clone())]), Some((0.0, 0.0)));
        // Pooled with a noiseless pair of the same level: half the variance, noise / sqrt(2).
        let (pooled, _) = relative_noise(&[(a.clone(), b), (a.clone(), a)]).unwrap();
        assert!((pooled - want / 2f64.sqrt()).abs() < 1e-6, "{pooled}");
        let black = Image::from_pixels(3, 2, vec![[0.0; 3]; 6], vec![1.0; 6]).unwrap();
        assert_eq!(relative_noise(&[(black.clone(), black)]), None);
    }
}
