//! The renderer before issue 16 (commit 1a8cad1: one-sample MIS, the constant environment
//! sampled over the whole sphere, the lobe-fit BRDF sampling, independent numbers), measured
//! the way `experiments bench render-noise` measures today's: 256 px sphere, 64 spp, relative
//! noise pooled over pairs of seeds (1 and 2, 3 and 4, ...), the share of it in the 0.1% of
//! pixels with the largest differences, and the efficiency 1 / (noise^2 x s) per wall and per
//! CPU second. The "before" column of the README's render-noise row. Run it in a worktree of
//! that commit (it uses that commit's API):
//!
//! ```sh
//! git worktree add /tmp/before 1a8cad1
//! cp docs/bench/render_noise_before.rs /tmp/before/crates/deepbrdf-render/examples/
//! experiments tabulate --material rgl/cg_sunflower_rgb --out mats   # today's tables, as files
//! cd /tmp/before && RAYON_NUM_THREADS=2 cargo run --release -p deepbrdf-render \
//!     --example render_noise_before -- mats/cg_sunflower_rgb.binary 4 'sun:40,30;const'
//! ```
use deepbrdf_data::cache::Cache;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::Silent;
use deepbrdf_render::*;
use std::time::Instant;

/// Pooled relative noise and the top 0.1% share: a copy of `relative_noise` in
/// `crates/experiments/src/commands/bench/render_noise.rs` (this file builds against the old
/// commit, which has neither).
fn noise(pairs: &[(Image, Image)]) -> (f64, f64) {
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
            let m = |p: &[f32; 3]| p.iter().map(|&v| f64::from(v)).sum::<f64>() / 3.0;
            diffs.push(m(p) - m(q));
            sum += 0.5 * (m(p) + m(q));
        }
        let n = diffs.len() as f64;
        let mean = diffs.iter().sum::<f64>() / n;
        let mut sq: Vec<f64> = diffs.iter().map(|x| (x - mean).powi(2)).collect();
        sq.sort_unstable_by(|x, y| y.total_cmp(x));
        let total: f64 = sq.iter().sum();
        top_sum += sq[..diffs.len().div_ceil(1000)].iter().sum::<f64>();
        total_sum += total;
        var_sum += total / (n - 1.0);
        level_sum += sum / n;
    }
    let m = pairs.len() as f64;
    ((var_sum / m / 2.0).sqrt() / (level_sum / m), if total_sum > 0.0 { top_sum / total_sum } else { 0.0 })
}

/// CPU seconds of this process so far (Linux, 100 ticks per second).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat");
    let fields: Vec<&str> = stat.rsplit_once(')').expect("stat").1.split_whitespace().collect();
    (fields[11].parse::<f64>().expect("utime") + fields[12].parse::<f64>().expect("stime")) / 100.0
}

fn main() {
    let mut args = std::env::args().skip(1);
    let materials: Vec<String> =
        args.next().expect("materials").split(',').map(String::from).collect();
    let pairs: u64 = args.next().map_or(4, |s| s.parse().expect("pairs"));
    let lights = args.next().unwrap_or_else(|| "sun:40,30;const".into());
    let cache = Cache::at(std::env::temp_dir().join("deepbrdf-before-cache"));
    let tables: Vec<_> =
        materials.iter().map(|m| load_material(m, &cache).expect("material")).collect();
    let mut brdfs: Vec<(String, Box<dyn Brdf + '_>)> = vec![
        ("lambertian 0.5".into(), Box::new(Lambertian::new([0.5; 3]))),
        ("plastic (lambertian + ggx 0.1)".into(), Box::new(Sum::plastic([0.3, 0.2, 0.1], 0.1, [0.04; 3]))),
    ];
    for (name, table) in &tables {
        brdfs.push((name.clone(), Box::new(MerlBrdf::new(table))));
    }
    println!("renderer of 1a8cad1, 256x256 sphere, 64 spp, noise pooled over {pairs} pairs");
    println!("material light s/image cpu-s noise top efficiency eff.(cpu)");
    for light in lights.split(';') {
        let scene = SceneConfig { light: light.parse().expect("light"), ..Default::default() }
            .build()
            .expect("scene");
        for (name, brdf) in &brdfs {
            let renders = (2 * pairs) as f64;
            let (mut images, mut seconds, cpu_start) = (Vec::new(), 0.0, cpu_seconds());
            for pair in 0..pairs {
                let mut one = |seed| {
                    let settings = RenderSettings { size: 256, spp: 64, seed, jitter: true };
                    let start = Instant::now();
                    let image = render(&scene, brdf.as_ref(), &settings, &Silent).expect("render");
                    seconds += start.elapsed().as_secs_f64() / renders;
                    image
                };
                images.push((one(2 * pair + 1), one(2 * pair + 2)));
            }
            let cpu = (cpu_seconds() - cpu_start) / renders;
            let (noise, top) = noise(&images);
            let eff = |s: f64| 1.0 / (noise * noise * s);
            println!("{name:<34} {light:<10} {seconds:.3} {cpu:.2} {noise:.4} {top:.3} {:.1} {:.1}", eff(seconds), eff(cpu));
        }
    }
}
