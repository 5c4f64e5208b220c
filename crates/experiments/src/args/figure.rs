//! `--size PX --spp N --seed S`: how the paper's figures are rendered (`figures-quality`,
//! `figures-editing`, `interpolate`): tiles large enough, and sampled densely enough, that the
//! renderer's grain is not what a reader sees. The measures beside a figure keep their own
//! fixed settings ([`ImageRelaeConfig::default`]).
use deepbrdf_eval::metrics::ImageRelaeConfig;

#[derive(Debug, Clone, clap::Args)]
pub struct FigureArg {
    /// The figures' tile size in pixels.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(16..=1024))]
    pub size: u32,
    /// The figures' samples per pixel (Sobol points).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub spp: u32,
    /// Seed of the figures' renders (their noise measure's second render uses the next one).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
}

impl FigureArg {
    /// The figures' scene and render settings.
    pub fn config(&self) -> anyhow::Result<ImageRelaeConfig> {
        let config = ImageRelaeConfig::figure(self.size, self.spp, self.seed);
        config.render.validate()?;
        Ok(config)
    }
}
