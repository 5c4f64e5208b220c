//! `experiments bench render`: speed of the renderer (target: a 256 x 256 sphere of a
//! tabulated MERL material under sun and sky at 64 spp in under 0.5 s on 2 cores). Prints MERL
//! lookups per second, images per second, and the cost of the tabulated material relative to an
//! analytic one measured in the same run.
use super::cpu_time::cpu_seconds;
use crate::args::data::CacheArg;
use anyhow::Context;
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::{MerlTable, Progress, Silent};
use deepbrdf_render::brdf::{sample_cosine_hemisphere, InterleavedTable, Rgb};
use deepbrdf_render::geometry::Vec3;
use deepbrdf_render::{
    render, Brdf, MerlBrdf, MerlLookup, RenderSettings, Sampler, SceneConfig, Sum,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The tabulated material: a bundled name or a MERL .binary file.
    #[arg(long, default_value = "gold-metallic-paint")]
    pub material: String,
    /// Image side in pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub size: u32,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: u32,
    /// Timed renders per material (after one untimed warm-up); best and median are reported.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub repeats: u32,
    /// Direction pairs for the lookup benchmark.
    #[arg(long, default_value_t = 2_000_000, value_parser = clap::value_parser!(u32).range(1..))]
    pub lookups: u32,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// A BRDF that counts its evaluations (for lookups per second during a render).
struct Counting<'a> {
    inner: &'a dyn Brdf,
    evals: AtomicU64,
}

impl Brdf for Counting<'_> {
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        if wi.z > 0.0 && wo.z > 0.0 {
            self.evals.fetch_add(1, Ordering::Relaxed);
        }
        self.inner.eval(wi, wo)
    }
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        self.inner.sample(wo, u)
    }
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        self.inner.pdf(wi, wo)
    }
}

/// Timings of `repeats` calls (after one warm-up call).
struct Timing {
    best: f64,
    median: f64,
    /// CPU seconds per call, all threads together (robust to other load on the machine).
    cpu: Option<f64>,
}

fn time_repeats(repeats: u32, mut f: impl FnMut() -> anyhow::Result<()>) -> anyhow::Result<Timing> {
    f()?;
    let mut t = Vec::with_capacity(repeats as usize);
    let cpu_start = cpu_seconds();
    for _ in 0..repeats {
        let start = Instant::now();
        f()?;
        t.push(start.elapsed().as_secs_f64());
    }
    let cpu = cpu_start.zip(cpu_seconds()).map(|(a, b)| (b - a) / f64::from(repeats));
    t.sort_by(f64::total_cmp);
    Ok(Timing { best: t[0], median: t[(t.len() - 1) / 2], cpu })
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let (name, table) = load_material(&args.material, &args.cache.cache())
        .with_context(|| format!("loading material '{}'", args.material))?;
    let threads = rayon::current_num_threads();
    println!("bench render: {name}, {threads} threads (set RAYON_NUM_THREADS to change)");

    bench_lookups(&table, args.lookups);
    let results = bench_renders(&args, &table, threads)?;
    println!(
        "tabulated / analytic time in this run: {:.2} (interpolated), {:.2} (nearest); target: 256x256 at 64 spp < 0.5 s on 2 threads",
        results[0] / results[2],
        results[1] / results[2]
    );
    Ok(())
}

/// MERL lookups on one thread at `count` cosine-distributed direction pairs, by the renderer's
/// interleaved table and by the data layer's (interpolated and nearest), printed.
fn bench_lookups(table: &MerlTable, count: u32) {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let pairs: Vec<([f64; 3], [f64; 3])> = (0..count)
        .map(|_| {
            let mut dir = || sample_cosine_hemisphere([rng.random(), rng.random()]).to_array();
            (dir(), dir())
        })
        .collect();
    let fast = InterleavedTable::new(table);
    let lookups: [(&str, &dyn Fn([f64; 3], [f64; 3]) -> [f32; 3]); 3] = [
        ("renderer, interleaved, interpolated", &|wi, wo| fast.lookup_interpolated(wi, wo)),
        ("data layer, interpolated", &|wi, wo| table.lookup_interpolated(wi, wo)),
        ("data layer, nearest", &|wi, wo| table.lookup_nearest(wi, wo)),
    ];
    for (label, lookup) in lookups {
        let start = Instant::now();
        let mut sum = 0f64;
        for &(wi, wo) in &pairs {
            sum += f64::from(black_box(lookup(wi, wo))[1]);
        }
        let s = start.elapsed().as_secs_f64();
        println!(
            "MERL lookups at random direction pairs ({label}; 1 thread): {:.1} M/s ({:.0} ns each; checksum {sum:.3e})",
            pairs.len() as f64 / s / 1e6,
            s / pairs.len() as f64 * 1e9
        );
    }
}

/// Whole renders of the preview sphere under sun and sky, of the table (interpolated and
/// nearest, with the lookups a render makes) and of an analytic Lambertian + GGX, printed;
/// returns the three median times.
fn bench_renders(args: &Args, table: &MerlTable, threads: usize) -> anyhow::Result<Vec<f64>> {
    let scene = SceneConfig::default().build()?;
    let settings = RenderSettings {
        size: args.size,
        spp: args.spp,
        seed: 0,
        jitter: true,
        sampler: Sampler::Sobol,
    };
    let merl = MerlBrdf::new(table);
    let analytic = Sum::plastic([0.3, 0.2, 0.1], 0.1, [0.04; 3]);
    let mut results = Vec::new();
    for (label, brdf) in [
        ("tabulated MERL (interpolated)", &merl as &dyn Brdf),
        ("tabulated MERL (nearest)", &merl.clone().with_lookup(MerlLookup::Nearest)),
        ("analytic Lambertian + GGX", &analytic),
    ] {
        let t = time_repeats(args.repeats, || {
            render(&scene, brdf, &settings, &Silent)?;
            Ok(())
        })?;
        println!(
            "render {label}: {0}x{0}, {1} spp, sun and sky: best {2:.3} s, median {3:.3} s ({4:.2} images/s), CPU {5} per image",
            args.size,
            args.spp,
            t.best,
            t.median,
            1.0 / t.median,
            t.cpu.map_or("n/a".to_string(), |c| format!("{c:.2} s")),
        );
        results.push(t.median);
        if label.starts_with("tabulated") {
            // Lookups made by one render (counted in an extra, untimed render: same seed, same
            // samples), over the timed renders' median.
            let counting = Counting { inner: brdf, evals: AtomicU64::new(0) };
            render(&scene, &counting, &settings, &Silent)?;
            let n = counting.evals.load(Ordering::Relaxed) as f64;
            println!(
                "  {:.2} M MERL lookups per image: {:.1} M lookups/s in the render ({threads} threads)",
                n / 1e6,
                n / t.median / 1e6
            );
        }
    }
    Ok(results)
}
