//! `experiments bench ...`: benchmarks that print speed numbers (the project's speed targets are
//! checked by these commands, not by timed tests).
use deepbrdf_data::Progress;

pub mod convert;
mod cpu_time;
pub mod edit;
pub mod io;
pub mod layers;
pub mod lookup;
pub mod model;
pub mod recover;
pub mod render;
pub mod render_noise;
pub mod render_set;
pub mod serve;
pub mod tabulate;
mod torch;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub what: What,
}

/// What to benchmark.
#[derive(Debug, clap::Subcommand)]
pub enum What {
    /// MERL .binary read and write speed (target: reading a 35 MB file well under 0.5 s).
    Io(io::Args),
    /// MERL table lookup speed, nearest and interpolated, one thread.
    Lookup(lookup::Args),
    /// Tabulating bundled NBRDF networks onto the MERL grid (target: 100 materials < 30 s).
    Tabulate(tabulate::Args),
    /// DeepBRDF training seconds per BRDF (cpu and paper presets) and decode seconds
    /// (target: decoding <= 0.15 s on 2 cores).
    Model(model::Args),
    /// Table 1's layers one by one: forward, input gradient and weight gradient, seconds and
    /// GFLOP/s beside one large matrix product's rate.
    Layers(layers::Args),
    /// Converting RGL measurements (.bsdf) to the MERL grid (target: <= 10 s per file on 2
    /// cores).
    Convert(convert::Args),
    /// Renderer speed: MERL lookups per second and images per second (target: a 256x256 sphere
    /// of a tabulated MERL material under sun and sky at 64 spp in < 0.5 s on 2 cores).
    Render(render::Args),
    /// One edit of §5.1: regressor, decode and a 128-pixel preview (target: <= 0.5 s on 2 cores).
    Edit(edit::Args),
    /// Renderer efficiency at equal noise: seconds per image, relative noise between two seeds
    /// and 1 / (noise^2 x s), per material and light.
    RenderNoise(render_noise::Args),
    /// Images per second of the recovery render set (§5.2) at its CPU default.
    RenderSet(render_set::Args),
    /// The browser editor over HTTP: preview latency and a burst of 20 slider moves (target:
    /// a 128-px preview in <= 300 ms on 2 cores).
    Serve(serve::Args),
    /// Seconds of one single-image recovery: prepare, network, decode (target: network +
    /// decode <= 0.5 s on 2 cores).
    Recover(recover::Args),
}

pub fn run(args: Args, progress: &dyn Progress) -> anyhow::Result<()> {
    match args.what {
        What::Io(a) => io::run(a, progress),
        What::Lookup(a) => lookup::run(a, progress),
        What::Tabulate(a) => tabulate::run(a, progress),
        What::Model(a) => model::run(a, progress),
        What::Layers(a) => layers::run(a, progress),
        What::Render(a) => render::run(a, progress),
        What::RenderNoise(a) => render_noise::run(a, progress),
        What::Convert(a) => convert::run(a, progress),
        What::Edit(a) => edit::run(a, progress),
        What::RenderSet(a) => render_set::run(a, progress),
        What::Recover(a) => recover::run(a, progress),
        What::Serve(a) => serve::run(a, progress),
    }
}
