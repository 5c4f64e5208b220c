//! The attribute changes of `edit` and `bench edit` (§5.1): `--diffuse R,G,B |
//! --diffuse-scale X`, `--specular R,G,B | --specular-scale X`, `--roughness X |
//! --roughness-scale X`.
use anyhow::bail;
use deepbrdf_eval::editing::{ColourEdit, Edit, ScalarEdit};

/// The attribute changes of an edit.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct EditArgs {
    /// Set the diffuse albedo (each in [0, 1]).
    #[arg(
        long,
        value_name = "R,G,B",
        conflicts_with = "diffuse_scale",
        allow_hyphen_values = true
    )]
    pub diffuse: Option<String>,
    /// Multiply the diffuse albedo.
    #[arg(long, value_name = "X", allow_hyphen_values = true)]
    pub diffuse_scale: Option<f64>,
    /// Set the specular albedo (each in [0, 1]).
    #[arg(
        long,
        value_name = "R,G,B",
        conflicts_with = "specular_scale",
        allow_hyphen_values = true
    )]
    pub specular: Option<String>,
    /// Multiply the specular albedo.
    #[arg(long, value_name = "X", allow_hyphen_values = true)]
    pub specular_scale: Option<f64>,
    /// Set the roughness (GGX alpha, > 0).
    #[arg(long, value_name = "X", conflicts_with = "roughness_scale", allow_hyphen_values = true)]
    pub roughness: Option<f64>,
    /// Multiply the roughness.
    #[arg(long, value_name = "X", allow_hyphen_values = true)]
    pub roughness_scale: Option<f64>,
}

fn rgb(flag: &str, text: &str) -> anyhow::Result<[f64; 3]> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let values: Option<Vec<f64>> = parts.iter().map(|p| p.parse::<f64>().ok()).collect();
    match values {
        Some(v) if v.len() == 3 => Ok([v[0], v[1], v[2]]),
        _ => bail!("--{flag} '{text}': expected three numbers R,G,B"),
    }
}

impl EditArgs {
    /// The edit these arguments ask for (values are checked when it is applied).
    pub fn edit(&self) -> anyhow::Result<Edit> {
        let colour = |flag: &str, set: &Option<String>, scale: Option<f64>| {
            let set = set.as_deref().map(|text| rgb(flag, text)).transpose()?;
            anyhow::Ok(ColourEdit::set_or_scale(flag, set, scale)?)
        };
        Ok(Edit {
            diffuse: colour("diffuse", &self.diffuse, self.diffuse_scale)?,
            specular: colour("specular", &self.specular, self.specular_scale)?,
            roughness: ScalarEdit::set_or_scale("roughness", self.roughness, self.roughness_scale)?,
        })
    }
}
