//! Edits measured against a known answer: a material whose parameters are known is edited
//! (roughness, an albedo, a colour), and the same material with the parameter changed is what
//! the edit should reach. How far the edited table ends from that answer, against how far the
//! unedited material is, says whether the edit helped: a ratio below 1 moved towards the answer,
//! at most 0.5 removed half of the distance at least, above 1 ended farther than doing nothing.
//! Distances are image RelAE against the answer's render ([`ImageRelae`]: the answer rendered
//! once, every candidate with the same random numbers).

pub mod suite;

use crate::error::{EvalError, Result};
use crate::metrics::{ImageRelae, ImageRelaeConfig};
use crate::stats::finite_median;
use deepbrdf_data::albedo::directional_albedo;
use deepbrdf_data::rgl::export::luminance;
use deepbrdf_data::MerlTable;
use std::fmt::Write as _;

/// The bar of an edit against its answer: the edited table's distance at most this share of
/// the unedited one's.
pub const HALF_WAY: f64 = 0.5;

/// One edit of one material by one method, against the answer.
#[derive(Clone, Debug, PartialEq)]
pub struct KnownEdit {
    pub material: String,
    /// The edit's name (e.g. "roughness x2").
    pub edit: String,
    /// The method's name (e.g. "DeepBRDF residual", "analytic").
    pub method: String,
    /// Image RelAE of the unedited material against the answer.
    pub unedited: f64,
    /// Image RelAE of the edited table against the answer.
    pub edited: f64,
    /// Whether the edit left a dark hole at the highlight that the original did not have
    /// ([`super::lobe::dark_hole`]); `None` where the lobe could not be read.
    pub dark_hole: Option<bool>,
    /// The largest relative difference of the edited table's directional albedo from the
    /// answer's over [`ALBEDO_ANGLES_DEG`] ([`albedo_error`]).
    pub albedo_error: f64,
}

impl KnownEdit {
    /// `edited / unedited`: below 1 the edit moved towards the answer.
    pub fn ratio(&self) -> f64 {
        self.edited / self.unedited
    }

    /// Whether the edit removed at least half of the distance ([`HALF_WAY`]).
    pub fn halves(&self) -> bool {
        self.ratio() <= HALF_WAY
    }

    /// Whether the edit ended farther from the answer than the unedited material.
    pub fn farther(&self) -> bool {
        !(self.ratio() <= 1.0)
    }

    /// Whether the edit reflects what the answer reflects, within [`ALBEDO_TOLERANCE`], from
    /// every incidence of [`ALBEDO_ANGLES_DEG`].
    pub fn albedo_kept(&self) -> bool {
        self.albedo_error <= ALBEDO_TOLERANCE
    }
}

/// Incidence angles (degrees) at which an edit's energy is compared with the answer's: grazing
/// ones included, where a floor or a table top is seen.
pub const ALBEDO_ANGLES_DEG: [f64; 5] = [0.0, 30.0, 60.0, 75.0, 85.0];
/// Relative albedo difference within which an edit keeps the answer's energy.
pub const ALBEDO_TOLERANCE: f64 = 0.1;

/// The directional albedo's luminance of `table` at each of [`ALBEDO_ANGLES_DEG`]
/// ([`deepbrdf_data::albedo`]).
pub fn albedos(table: &MerlTable) -> [f64; 5] {
    ALBEDO_ANGLES_DEG.map(|deg| luminance(directional_albedo(table, deg.to_radians())))
}

/// The largest `|a_edited / a_answer - 1|` over [`ALBEDO_ANGLES_DEG`], from the answer's
/// [`albedos`] (infinite where the answer reflects nothing and the edit does).
pub fn albedo_error(answer: &[f64; 5], edited: &MerlTable) -> f64 {
    answer
        .iter()
        .zip(albedos(edited))
        .map(|(&want, got)| match want > 0.0 {
            true => (got / want - 1.0).abs(),
            false if got > 0.0 => f64::INFINITY,
            false => 0.0,
        })
        .fold(0.0, f64::max)
}

/// The distances of `original` (unedited) and of each of `edited` from `answer`, in that order
/// of `edited`: `(unedited, [edited...])`. Fails when the answer renders black (no distance is
/// defined) or the original already equals it (nothing to edit).
pub fn distances(
    answer: &MerlTable,
    original: &MerlTable,
    edited: &[&MerlTable],
    config: &ImageRelaeConfig,
) -> Result<(f64, Vec<f64>)> {
    let measure = ImageRelae::new(answer, config)?;
    let unedited = measure.measure(original)?;
    if !(unedited > 0.0) {
        return Err(EvalError::Invalid(format!(
            "the unedited material is at distance {unedited} from the answer: nothing to edit"
        )));
    }
    let edited = edited.iter().map(|t| measure.measure(t)).collect::<Result<Vec<_>>>()?;
    Ok((unedited, edited))
}

/// A method's record over a set of known-answer edits.
#[derive(Clone, Debug, PartialEq)]
pub struct KnownTally {
    pub edits: usize,
    /// Edits that removed at least half of the distance.
    pub halved: usize,
    /// Edits that ended farther than the unedited material.
    pub farther: usize,
    /// Median of [`KnownEdit::ratio`] (NaN for no edit).
    pub median_ratio: f64,
    /// Edits that left a dark hole.
    pub dark_holes: usize,
    /// Edits whose albedo stayed within [`ALBEDO_TOLERANCE`] of the answer's.
    pub albedo_kept: usize,
}

impl KnownTally {
    /// The tally of `rows`.
    pub fn of<'a>(rows: impl IntoIterator<Item = &'a KnownEdit>) -> Self {
        let rows: Vec<&KnownEdit> = rows.into_iter().collect();
        let ratios: Vec<f64> = rows.iter().map(|r| r.ratio()).collect();
        Self {
            edits: rows.len(),
            halved: rows.iter().filter(|r| r.halves()).count(),
            farther: rows.iter().filter(|r| r.farther()).count(),
            median_ratio: finite_median(ratios),
            dark_holes: rows.iter().filter(|r| r.dark_hole == Some(true)).count(),
            albedo_kept: rows.iter().filter(|r| r.albedo_kept()).count(),
        }
    }
}

/// The summary table: one row per method and edit (in first-seen order), then one per method
/// over all its edits: edits, halved, farther, median ratio, dark holes.
pub fn markdown(rows: &[KnownEdit]) -> String {
    let mut methods: Vec<&str> = Vec::new();
    let mut edits: Vec<&str> = Vec::new();
    for r in rows {
        if !methods.contains(&r.method.as_str()) {
            methods.push(&r.method);
        }
        if !edits.contains(&r.edit.as_str()) {
            edits.push(&r.edit);
        }
    }
    let mut md = String::from(
        "| method | edit | edits | at most half as far | farther than unedited | median ratio | dark holes | albedo within 10% at 0-85 deg |\n\
         | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    let mut line = |method: &str, edit: &str, t: KnownTally| {
        let _ = writeln!(
            md,
            "| {method} | {edit} | {} | {} | {} | {:.3} | {} | {} |",
            t.edits, t.halved, t.farther, t.median_ratio, t.dark_holes, t.albedo_kept
        );
    };
    for &method in &methods {
        for &edit in &edits {
            let t = KnownTally::of(rows.iter().filter(|r| r.method == method && r.edit == edit));
            if t.edits > 0 {
                line(method, edit, t);
            }
        }
        line(method, "**all**", KnownTally::of(rows.iter().filter(|r| r.method == method)));
    }
    md
}

/// The rows as CSV (material, edit, method, unedited, edited, ratio, halves, farther, dark
/// hole: yes, no, or empty where not measured; the albedo error).
pub fn csv(rows: &[KnownEdit]) -> String {
    let mut out = String::from(
        "material,edit,method,unedited_relae,edited_relae,ratio,halves,farther,dark_hole,albedo_error\n",
    );
    for r in rows {
        let hole = match r.dark_hole {
            Some(true) => "yes",
            Some(false) => "no",
            None => "",
        };
        let _ = writeln!(
            out,
            "{},{},{},{:.6},{:.6},{:.6},{},{},{hole},{:.6}",
            r.material,
            r.edit,
            r.method,
            r.unedited,
            r.edited,
            r.ratio(),
            r.halves(),
            r.farther(),
            r.albedo_error
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::testing::synthetic_table;
    use deepbrdf_render::{RenderSettings, Sampler};

    fn row(method: &str, edit: &str, unedited: f64, edited: f64) -> KnownEdit {
        KnownEdit {
            material: "m".into(),
            edit: edit.into(),
            method: method.into(),
            unedited,
            edited,
            dark_hole: Some(edited > unedited),
            albedo_error: edited,
        }
    }

    #[test]
    fn tallies_count_halved_and_farther_edits() {
        let rows = [
            row("a", "x2", 0.2, 0.1),  // exactly half: halves
            row("a", "x2", 0.2, 0.21), // farther
            row("a", "x0.5", 0.2, 0.15),
            row("b", "x2", 0.2, f64::NAN), // a failed measure counts as farther
        ];
        let t = KnownTally::of(&rows[..3]);
        assert_eq!((t.edits, t.halved, t.farther), (3, 1, 1));
        assert!((t.median_ratio - 0.75).abs() < 1e-12);
        assert!(rows[3].farther() && !rows[3].halves());
        let md = markdown(&rows);
        assert_eq!(t.dark_holes, 1);
        assert!(md.contains("| a | x2 | 2 | 1 | 1 |"), "{md}");
        // Albedo errors (here the edited distances) 0.1, 0.21, 0.15: one within 10%.
        assert!(md.contains("| a | **all** | 3 | 1 | 1 | 0.750 | 1 | 1 |"), "{md}");
        assert!(md.contains("| b | x2 | 1 | 0 | 1 |"), "{md}");
        let csv = csv(&rows);
        assert_eq!(csv.lines().count(), 5);
        assert!(csv.lines().nth(2).unwrap().ends_with(",true,yes,0.210000"), "{csv}");
    }

    #[test]
    fn distances_are_zero_at_the_answer_and_grow_away_from_it() {
        let config = ImageRelaeConfig {
            render: RenderSettings {
                size: 24,
                spp: 2,
                seed: 3,
                jitter: true,
                sampler: Sampler::Independent,
            },
            ..Default::default()
        };
        let answer = synthetic_table(4);
        let scaled = |s: f32| {
            let mut t = answer.clone();
            t.values_mut().iter_mut().filter(|v| **v >= 0.0).for_each(|v| *v *= s);
            t
        };
        let (original, near) = (scaled(0.5), scaled(0.9));
        let (unedited, edited) = distances(&answer, &original, &[&near, &answer], &config).unwrap();
        assert!((unedited - 0.5).abs() < 1e-4, "{unedited}");
        assert!((edited[0] - 0.1).abs() < 1e-4, "{edited:?}");
        assert_eq!(edited[1], 0.0);
        assert!(distances(&answer, &answer, &[], &config).is_err());
    }
}
