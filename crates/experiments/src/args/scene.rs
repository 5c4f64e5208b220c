//! The scene and rendering arguments shared by `render`, `compare` and `sheet`:
//! `--shape`, `--light`, `--view`, `--fov`, `--size`, `--spp`, `--seed`, `--sampler`,
//! `--exposure`.
use anyhow::Context;
use deepbrdf_render::{
    LightSpec, Projection, RenderSettings, Sampler, Scene, SceneConfig, Shape, Tonemap,
};

#[derive(Debug, Clone, clap::Args)]
pub struct SceneArgs {
    /// Shape: sphere, plane, torus, ellipsoid or cylinder.
    #[arg(long, default_value = "sphere")]
    pub shape: String,
    /// Lighting: sun:ELEV,AZIM[,TURBIDITY] (Preetham sun and sky, degrees), dir:THETA,PHI (a
    /// directional light, degrees from the zenith and from +x) or const[:L] (constant
    /// environment).
    #[arg(long, default_value = "sun:40,30")]
    pub light: String,
    /// Viewpoint THETA,PHI in degrees: polar angle from the zenith and azimuth from +x of the
    /// direction from the object to the camera.
    #[arg(long, value_name = "THETA,PHI", default_value = "70,0")]
    pub view: String,
    /// Perspective camera with this vertical field of view (degrees); orthographic without it.
    #[arg(long, value_name = "DEG")]
    pub fov: Option<f64>,
    /// Image width and height in pixels [default: 256; 128 per tile for `sheet`].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=8192))]
    pub size: Option<u32>,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub spp: u32,
    /// Seed of the Monte Carlo sampling.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Random numbers: sobol (per-pixel Owen-scrambled Sobol points, less noise) or independent.
    #[arg(long, default_value = "sobol")]
    pub sampler: Sampler,
    /// Exposure multiplier applied before tonemapping to 8-bit sRGB.
    #[arg(long, default_value_t = 1.0)]
    pub exposure: f32,
}

/// Everything a rendering command sets up from [`SceneArgs`]: the scene's description, the built
/// scene, the render settings and the tonemapping.
pub struct SceneSetup {
    pub config: SceneConfig,
    pub scene: Scene,
    pub settings: RenderSettings,
    pub tonemap: Tonemap,
}

impl SceneSetup {
    /// `"256x256 sun ... on a sphere, 64 spp"`, as the commands print it.
    pub fn description(&self) -> String {
        format!(
            "{}x{} {} on a {}, {} spp",
            self.settings.size,
            self.settings.size,
            self.config.light,
            self.config.shape,
            self.settings.spp
        )
    }
}

impl SceneArgs {
    /// The scene, settings (`default_size` when `--size` is not given) and tonemapping of these
    /// arguments, checked and built: the one setup of `render`, `compare` and `sheet`.
    pub fn setup(&self, default_size: u32) -> anyhow::Result<SceneSetup> {
        let config = self.scene()?;
        let settings = self.settings(default_size);
        let tonemap = self.tonemap()?;
        let scene = config.build()?;
        Ok(SceneSetup { config, scene, settings, tonemap })
    }

    /// The scene these arguments describe.
    fn scene(&self) -> anyhow::Result<SceneConfig> {
        let shape: Shape = self.shape.parse()?;
        let light: LightSpec = self.light.parse()?;
        let (theta, phi) = self
            .view
            .split_once(',')
            .and_then(|(a, b)| Some((a.trim().parse::<f64>().ok()?, b.trim().parse::<f64>().ok()?)))
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .with_context(|| format!("--view '{}': expected THETA,PHI in degrees", self.view))?;
        let projection = match self.fov {
            Some(fov_deg) => Projection::Perspective { fov_deg },
            None => Projection::Orthographic,
        };
        Ok(SceneConfig { shape, light, view_theta_deg: theta, view_phi_deg: phi, projection })
    }

    /// Render settings, with `default_size` when `--size` is not given.
    fn settings(&self, default_size: u32) -> RenderSettings {
        RenderSettings {
            size: self.size.unwrap_or(default_size),
            spp: self.spp,
            seed: self.seed,
            jitter: true,
            sampler: self.sampler,
        }
    }

    /// The tonemapping of PNG output.
    fn tonemap(&self) -> anyhow::Result<Tonemap> {
        anyhow::ensure!(
            self.exposure.is_finite() && self.exposure > 0.0,
            "--exposure {} must be positive",
            self.exposure
        );
        Ok(Tonemap { exposure: self.exposure })
    }
}
