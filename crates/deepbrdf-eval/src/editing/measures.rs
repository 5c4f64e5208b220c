//! Measures of edits, interpolations and sweeps (beyond the paper, which only shows
//! pictures): how close an edit's re-estimated attributes come to the requested ones and how
//! much the untouched ones drift (leakage); the coefficient of variation of consecutive image
//! differences along a path; the monotonicity of a sweep; and the physical plausibility of a
//! decoded table (no negative values, directional albedo at most 1 at every incident angle).

use super::request::EditedAttribute;
use crate::attributes::Attributes;
use deepbrdf_data::merl::{CELLS, N_THETA_D};
use deepbrdf_data::MerlTable;

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn diff(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// `|a - b| / |b|` (Euclidean over the channels).
fn relative(a: &[f64], b: &[f64]) -> f64 {
    norm(&diff(a, b)) / norm(b).max(1e-12)
}

/// How an edit came out, from the attributes re-estimated on the decoded result.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditOutcome {
    /// `|achieved - requested| / |requested|` of the edited attribute (RGB norm for albedos);
    /// for the identity edit, NaN.
    pub target_error: f64,
    /// The achieved change as a fraction of the requested one, `(achieved - original) .
    /// (requested - original) / |requested - original|^2` (1: as requested; 0: no change);
    /// NaN for the identity edit.
    pub change_ratio: f64,
    /// Relative drift `|achieved - original| / |original|` of each attribute the edit did not
    /// touch (NaN for the edited one): diffuse, specular, roughness.
    pub diffuse_drift: f64,
    pub specular_drift: f64,
    pub roughness_drift: f64,
}

/// The outcome of an edit of `edited` that asked for `requested` starting from `original`,
/// given the attributes `achieved` re-estimated on the decoded table.
pub fn edit_outcome(
    original: &Attributes,
    requested: &Attributes,
    achieved: &Attributes,
    edited: EditedAttribute,
) -> EditOutcome {
    let pick = |a: &Attributes, which: EditedAttribute| -> Vec<f64> {
        match which {
            EditedAttribute::Diffuse => a.diffuse.to_vec(),
            EditedAttribute::Specular => a.specular.to_vec(),
            EditedAttribute::Roughness => vec![a.roughness],
            EditedAttribute::None => Vec::new(),
        }
    };
    let drift = |which: EditedAttribute| match which == edited {
        true => f64::NAN,
        false => relative(&pick(achieved, which), &pick(original, which)),
    };
    let (target_error, change_ratio) = match edited {
        EditedAttribute::None => (f64::NAN, f64::NAN),
        which => {
            let (o, r, a) = (pick(original, which), pick(requested, which), pick(achieved, which));
            let wanted = diff(&r, &o);
            let got = diff(&a, &o);
            let dot: f64 = wanted.iter().zip(&got).map(|(x, y)| x * y).sum();
            (relative(&a, &r), dot / norm(&wanted).powi(2).max(1e-24))
        }
    };
    EditOutcome {
        target_error,
        change_ratio,
        diffuse_drift: drift(EditedAttribute::Diffuse),
        specular_drift: drift(EditedAttribute::Specular),
        roughness_drift: drift(EditedAttribute::Roughness),
    }
}

/// Standard deviation over mean of `values` (population deviation; 0 for equal values).
pub fn coefficient_of_variation(values: &[f64]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    var.sqrt() / mean.abs().max(1e-300)
}

/// Whether `values` never decrease (`increasing`) or never increase, allowing steps against
/// the direction of at most `tolerance` times the whole range.
pub fn is_monotone(values: &[f64], increasing: bool, tolerance: f64) -> bool {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let slack = tolerance * (hi - lo).abs();
    values.windows(2).all(|w| match increasing {
        true => w[1] >= w[0] - slack,
        false => w[1] <= w[0] + slack,
    })
}

pub use deepbrdf_data::albedo::directional_albedo;

/// The physical plausibility of a table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plausibility {
    /// Values below zero among the valid cells (invalid cells are negative by MERL's
    /// convention and not counted).
    pub negative_values: usize,
    /// Largest directional albedo over the channels and the incident angles 0, 5, ..., 85
    /// degrees.
    pub max_albedo: f64,
    /// The incident angle (degrees) of `max_albedo`.
    pub max_albedo_theta_deg: f64,
}

impl Plausibility {
    /// No negative value and no albedo above 1.
    pub fn is_plausible(&self) -> bool {
        self.negative_values == 0 && self.max_albedo <= 1.0
    }
}

/// Checks `table` (see [`Plausibility`]).
pub fn plausibility(table: &MerlTable) -> Plausibility {
    let v = table.values();
    let negative_values = (0..CELLS)
        .filter(|&cell| table.is_valid(cell))
        .map(|cell| (0..3).filter(|&c| v[c * CELLS + cell] < 0.0).count())
        .sum();
    let mut best = (f64::NEG_INFINITY, 0.0);
    for step in 0..N_THETA_D / 5 {
        let deg = 5.0 * step as f64;
        let a = directional_albedo(table, deg.to_radians());
        let m = a.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if m > best.0 {
            best = (m, deg);
        }
    }
    Plausibility { negative_values, max_albedo: best.0, max_albedo_theta_deg: best.1 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::testing::analytic::lambertian_table;

    #[test]
    fn outcomes_of_perfect_and_leaky_edits() {
        let o = Attributes { diffuse: [0.4, 0.2, 0.1], specular: [0.05; 3], roughness: 0.1 };
        let r = Attributes { diffuse: [0.2, 0.1, 0.05], ..o };
        let perfect = edit_outcome(&o, &r, &r, EditedAttribute::Diffuse);
        assert!(perfect.target_error < 1e-12 && (perfect.change_ratio - 1.0).abs() < 1e-12);
        assert!(perfect.diffuse_drift.is_nan() && perfect.roughness_drift == 0.0);
        let nothing = edit_outcome(&o, &r, &o, EditedAttribute::Diffuse);
        assert!((nothing.target_error - 1.0).abs() < 1e-12 && nothing.change_ratio.abs() < 1e-12);
        let leaky = Attributes { roughness: 0.12, ..r };
        let e = edit_outcome(&o, &r, &leaky, EditedAttribute::Diffuse);
        assert!((e.roughness_drift - 0.2).abs() < 1e-9, "{e:?}");
        let id = edit_outcome(&o, &o, &o, EditedAttribute::None);
        assert!(id.target_error.is_nan() && id.specular_drift == 0.0);
    }

    #[test]
    fn sequences_and_plausibility() {
        assert!(coefficient_of_variation(&[2.0, 2.0, 2.0]) < 1e-15);
        assert!((coefficient_of_variation(&[1.0, 3.0]) - 0.5).abs() < 1e-12);
        assert!(is_monotone(&[0.1, 0.2, 0.2, 0.5], true, 0.0));
        assert!(!is_monotone(&[0.1, 0.3, 0.2, 0.5], true, 0.0));
        assert!(is_monotone(&[0.1, 0.3, 0.29, 0.5], true, 0.05));
        assert!(is_monotone(&[0.5, 0.2], false, 0.0));
        // A Lambertian table of albedo 0.5 reflects 0.5 at every angle; 1.2 is implausible.
        let half = lambertian_table([0.5, 0.5, 0.5]);
        for deg in [0.0f64, 40.0, 80.0] {
            let a = directional_albedo(&half, deg.to_radians());
            assert!(a.iter().all(|v| (v - 0.5).abs() < 0.01), "{deg}: {a:?}");
        }
        let p = plausibility(&half);
        assert!(p.is_plausible() && p.negative_values == 0, "{p:?}");
        let p = plausibility(&lambertian_table([1.2, 0.2, 0.2]));
        assert!(!p.is_plausible() && p.max_albedo > 1.1, "{p:?}");
    }
}
