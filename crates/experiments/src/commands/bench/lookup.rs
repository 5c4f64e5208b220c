//! `experiments bench lookup`: single-thread speed of `MerlTable::lookup_nearest` and
//! `lookup_interpolated` (a renderer calls them millions of times per second).
use deepbrdf_data::merl::coords::direction;
use deepbrdf_data::testing::{ggx, tabulate, Ggx};
use deepbrdf_data::Progress;
use std::hint::black_box;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Number of direction pairs looked up per method.
    #[arg(long, default_value_t = 2_000_000, value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    pub pairs: u64,
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    let lobe = Ggx { alpha: 0.2, f0: [0.04, 0.3, 0.9], diffuse: [0.1, 0.1, 0.1] };
    progress.start(3, "bench lookup");
    let table = tabulate(|wi, wo| ggx(&lobe, wi, wo));
    progress.advance(1);
    // Deterministic pseudo-random upper-hemisphere directions (a cheap LCG keeps the benchmark's
    // own cost out of the timing: the pairs are generated before).
    let n = args.pairs as usize;
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = || {
        state =
            state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let pairs: Vec<([f64; 3], [f64; 3])> = (0..n)
        .map(|_| {
            let wi = direction(next().acos(), next() * std::f64::consts::TAU);
            let wo = direction(next().acos(), next() * std::f64::consts::TAU);
            (wi, wo)
        })
        .collect();
    let t = Instant::now();
    let mut sum = 0f32;
    for &(wi, wo) in &pairs {
        sum += black_box(table.lookup_nearest(wi, wo))[1];
    }
    let nearest = t.elapsed().as_secs_f64();
    progress.advance(1);
    let t = Instant::now();
    for &(wi, wo) in &pairs {
        sum += black_box(table.lookup_interpolated(wi, wo))[1];
    }
    let interp = t.elapsed().as_secs_f64();
    progress.advance(1);
    progress.finish();
    black_box(sum);
    println!("MERL table lookups, {n} random direction pairs, one thread");
    println!("{:14} {:>10} {:>14}", "method", "s", "M lookups/s");
    for (name, s) in [("nearest", nearest), ("interpolated", interp)] {
        println!("{name:14} {s:>10.3} {:>14.1}", n as f64 / s.max(1e-9) / 1e6);
    }
    Ok(())
}
