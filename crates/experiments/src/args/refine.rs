//! The `--refine N` and `--refine-radiance P` options of the commands that encode with a
//! `slice` model (`encode`, `reconstruct`, `baselines`, `sweep-k`): how many Levenberg-Marquardt
//! steps refine each encoding through the decoder, and on which error
//! (`deepbrdf_model::refine`).
use anyhow::bail;
use deepbrdf_model::refine::Refinement;

#[derive(Debug, Clone, clap::Args)]
pub struct RefineArg {
    /// Levenberg-Marquardt steps refining a `slice` model's encoding through its decoder
    /// (0: the encoder's latent as it is; other presets ignore it).
    #[arg(long, value_name = "N", default_value_t = Refinement::default().iterations)]
    pub refine: usize,
    /// Weigh the refined error of each (theta_h, theta_d) cell by its radiance sensitivity
    /// ((rho + rho_ref) cos theta_i cos theta_o) to the power 2P: 0 is eq. (4)'s mapped error,
    /// 1 a cosine-weighted error of the linear BRDF (in 0..=1).
    #[arg(long, value_name = "P", default_value_t = Refinement::default().radiance_power)]
    pub refine_radiance: f64,
}

impl RefineArg {
    /// The refinement asked for.
    pub fn refinement(&self) -> anyhow::Result<Refinement> {
        if !(0.0..=1.0).contains(&self.refine_radiance) {
            bail!("--refine-radiance {}: expected a number in 0..=1", self.refine_radiance);
        }
        Ok(Refinement { iterations: self.refine, radiance_power: self.refine_radiance })
    }
}
