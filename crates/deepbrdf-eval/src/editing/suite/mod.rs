//! The measured edit suite of §5.1 (`experiments figures-editing`): each material's attributes
//! edited as a user would edit them (diffuse albedo x0.5 and a hue change, specular albedo
//! x0.5, roughness x0.5 and x2, and the identity edit) by every representation and mode and by
//! the edits without a network, each result scored by the attributes re-estimated on it
//! against the request ([`edit_outcome`]), its plausibility ([`plausibility`]), the identity
//! edit's image RelAE, and the specular lobe a person sees against the original's
//! ([`judge_edit`]). [`report`] writes the rows as CSV and the tables of the summary.

pub mod report;

pub use report::{SuiteRow, SEPARATED, SUITE_METHODS};

use crate::attributes::{self, Attributes, FitConfig};
use crate::editing::{
    edit_outcome, judge_edit, plausibility, stretch_edit, ColourEdit, Edit, EditMode, Lobe,
    ScalarEdit, Space,
};
use crate::error::{EvalError, Result};
use crate::metrics::{ImageRelae, ImageRelaeConfig};
use crate::separation::{separated_attributes, SeparatedBasis};
use deepbrdf_data::{MerlTable, Progress};

/// The suite's name of its recolour: the diffuse channels rotated.
pub const HUE: &str = "diffuse hue";

/// The suite's name of the edit that changes nothing.
pub const IDENTITY: &str = "identity";

/// The names of the suite's edits, in the order of its tables.
pub const EDITS: [&str; 6] =
    [IDENTITY, "diffuse x0.5", HUE, "specular x0.5", "roughness x0.5", "roughness x2"];

/// The suite's edits of a material whose attributes are `a`: name ([`EDITS`]) and edit.
pub fn suite_edits(a: &Attributes) -> Vec<(&'static str, Edit)> {
    let edits = [
        Edit::default(),
        Edit { diffuse: Some(ColourEdit::Scale(0.5)), ..Edit::default() },
        Edit::rotated_diffuse(a.diffuse),
        Edit { specular: Some(ColourEdit::Scale(0.5)), ..Edit::default() },
        Edit { roughness: Some(ScalarEdit::Scale(0.5)), ..Edit::default() },
        Edit { roughness: Some(ScalarEdit::Scale(2.0)), ..Edit::default() },
    ];
    EDITS.into_iter().zip(edits).collect()
}

/// A representation the suite edits through: its name in the tables and its space (codec and
/// regressor).
pub struct SuiteRepresentation<'a> {
    pub name: &'static str,
    pub space: Space<'a>,
}

/// What the suite runs on.
pub struct SuiteInput<'a> {
    /// The materials' names, tables and fitted attributes, in the same order.
    pub names: &'a [String],
    pub tables: &'a [MerlTable],
    pub attributes: &'a [Attributes],
    /// Every `every`-th material is edited (1: all).
    pub every: usize,
    /// The representations, each edited in the paper's, the residual and the transfer mode.
    pub representations: &'a [SuiteRepresentation<'a>],
    /// Sun et al. 2018's split, whose stretch edit joins the suite where given.
    pub separation: Option<&'a SeparatedBasis>,
}

/// The suite's result: a row per material, method, mode and edit, and the edits whose lobe
/// could not be read (no valid cell where it is read), named.
pub struct Suite {
    /// Materials edited.
    pub materials: usize,
    pub rows: Vec<SuiteRow>,
    pub lobe_skipped: Vec<String>,
}

/// Runs the suite (see the module's documentation). An edit out of range for a material (x2
/// past the largest roughness) is left out; any other failure is an error.
pub fn run(input: &SuiteInput, progress: &dyn Progress) -> Result<Suite> {
    let n = input.tables.len();
    if input.names.len() != n || input.attributes.len() != n || input.every == 0 {
        return Err(EvalError::Invalid(format!(
            "the edit suite needs as many names and attributes as tables ({} and {} for {n}) \
             and a step of at least 1 (got {})",
            input.names.len(),
            input.attributes.len(),
            input.every
        )));
    }
    let chosen: Vec<usize> = (0..n).step_by(input.every).collect();
    let mut suite = Suite { materials: chosen.len(), rows: Vec::new(), lobe_skipped: Vec::new() };
    progress.start(chosen.len() as u64, "edit suite");
    for &m in &chosen {
        let material = Material::new(&input.names[m], &input.tables[m], &input.attributes[m]);
        material.edit_all(input, &mut suite)?;
        progress.advance(1);
    }
    progress.finish();
    Ok(suite)
}

/// One material of the suite and what its edits are judged against.
struct Material<'a> {
    name: &'a str,
    table: &'a MerlTable,
    original: &'a Attributes,
    quick: FitConfig,
    lobe: std::result::Result<Lobe, String>,
}

impl<'a> Material<'a> {
    fn new(name: &'a str, table: &'a MerlTable, original: &'a Attributes) -> Self {
        let lobe = Lobe::of(table).map_err(|e| format!("{name}: {e}"));
        Self { name, table, original, quick: FitConfig::quick(), lobe }
    }

    /// Every edit of the material by every method, pushed onto `suite`.
    fn edit_all(&self, input: &SuiteInput, suite: &mut Suite) -> Result<()> {
        if let Err(e) = &self.lobe {
            suite.lobe_skipped.push(e.clone());
        }
        let reference = ImageRelae::new(self.table, &ImageRelaeConfig::default())?;
        let (table, original) = (self.table, self.original);
        for rep in input.representations {
            let latent = rep.space.codec.encode(table)?;
            for mode in [EditMode::Paper, EditMode::Residual, EditMode::Nearest, EditMode::Transfer]
            {
                for (edit_name, edit) in suite_edits(original) {
                    let Ok(edited) = rep.space.edit(table, &latent, original, &edit, mode) else {
                        continue; // an edit out of range for this material (e.g. x2 past alpha 1)
                    };
                    let row = (rep.name, mode.name(), edit_name, &edit);
                    self.push(suite, &reference, row, &edited.requested, &edited.table)?;
                }
            }
        }
        let split = input.separation.map(|b| separated_attributes(b, table, original));
        for (edit_name, edit) in suite_edits(original) {
            let Ok(requested) = edit.apply(original) else { continue };
            for mode in [EditMode::Analytic, EditMode::Stretch, EditMode::Parts] {
                let edited = mode.edit_without_network(table, original, &requested)?;
                self.push(
                    suite,
                    &reference,
                    (mode.name(), "-", edit_name, &edit),
                    &requested,
                    &edited,
                )?;
            }
            // On the split, the recolour rotates the split's albedo; the outcome is judged
            // against the request of the fit, as the other methods' are.
            if let Some(split) = &split {
                let asked = match edit_name {
                    HUE => Edit::rotated_diffuse(split.diffuse),
                    _ => edit,
                };
                if let Ok(on_split) = asked.apply(split) {
                    let edited = stretch_edit(table, split, &on_split)?;
                    self.push(
                        suite,
                        &reference,
                        (SEPARATED, "-", edit_name, &edit),
                        &requested,
                        &edited,
                    )?;
                }
            }
        }
        Ok(())
    }

    /// Scores `edited`, the edit `row` = (method, mode, edit name, edit) asked as `requested`.
    fn push(
        &self,
        suite: &mut Suite,
        reference: &ImageRelae,
        (method, mode, edit_name, edit): (&'static str, &'static str, &'static str, &Edit),
        requested: &Attributes,
        edited: &MerlTable,
    ) -> Result<()> {
        let achieved = attributes::fit(edited, &self.quick)
            .map_err(|e| {
                EvalError::Invalid(format!(
                    "fitting the attributes of {}'s {method} {mode} {edit_name} edit: {e}",
                    self.name
                ))
            })?
            .attributes;
        let outcome = edit_outcome(self.original, requested, &achieved, edit.edited());
        let identity_relae = match edit_name {
            IDENTITY => reference.measure(edited)?,
            _ => f64::NAN,
        };
        let p = plausibility(edited);
        let lobe = match self.lobe.as_ref().map(|o| judge_edit(o, edited, edit)) {
            Ok(Ok(l)) => Some(l),
            Ok(Err(e)) => {
                let name = self.name;
                suite.lobe_skipped.push(format!("{name}, {method} {mode} {edit_name}: {e}"));
                None
            }
            Err(_) => None,
        };
        suite.rows.push(SuiteRow {
            material: self.name.to_string(),
            method,
            mode,
            edit: edit_name,
            outcome,
            identity_relae,
            plausible: p.is_plausible(),
            max_albedo: p.max_albedo,
            lobe,
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::Silent;

    /// Without a representation the suite runs the edits without a network: a row for each
    /// material, edit and method, the identity edit reproducing the table, each row in the CSV.
    #[test]
    fn without_a_network_it_scores_every_edit_of_every_chosen_material() {
        let attributes = [
            Attributes { diffuse: [0.3, 0.2, 0.1], specular: [0.04; 3], roughness: 0.1 },
            Attributes { diffuse: [0.05; 3], specular: [0.8, 0.6, 0.3], roughness: 0.3 },
            Attributes { diffuse: [0.5; 3], specular: [0.04; 3], roughness: 0.2 },
        ];
        let tables: Vec<MerlTable> = attributes.iter().map(Attributes::table).collect();
        let names: Vec<String> = ["plastic", "metal", "grey"].map(String::from).to_vec();
        let input = SuiteInput {
            names: &names,
            tables: &tables,
            attributes: &attributes,
            every: 2,
            representations: &[],
            separation: None,
        };
        let suite = run(&input, &Silent).unwrap();
        assert_eq!(suite.materials, 2);
        assert_eq!(
            suite.rows.len(),
            2 * EDITS.len() * 3,
            "two materials, analytic, stretch, parts"
        );
        let materials: Vec<&str> = suite.rows.iter().map(|r| r.material.as_str()).collect();
        assert!(materials.iter().all(|m| ["plastic", "grey"].contains(m)), "{materials:?}");
        for row in suite.rows.iter().filter(|r| r.edit == IDENTITY) {
            assert!(row.identity_relae < 1e-6, "{}: {}", row.method, row.identity_relae);
        }
        let halved = suite.rows.iter().find(|r| r.edit == "diffuse x0.5").unwrap();
        let floor = halved.lobe.as_ref().unwrap().comparison.floor_ratio;
        assert!((0.45..0.55).contains(&floor), "the diffuse floor x{floor}");
        assert_eq!(report::csv(&suite.rows).lines().count(), 1 + suite.rows.len());
        let summary = report::outcome_summary(&suite.rows);
        assert!(summary.contains("| stretch | roughness x2 | - |"), "{summary}");
        assert!(summary.contains("| parts | roughness x2 | - |"), "{summary}");
        // Every parts edit of these Lambertian + GGX tables halves the diffuse floor as asked.
        let parts = suite.rows.iter().filter(|r| r.method == "parts" && r.edit == "diffuse x0.5");
        for row in parts {
            let floor = row.lobe.as_ref().unwrap().comparison.floor_ratio;
            assert!((0.45..0.55).contains(&floor), "parts: the diffuse floor x{floor}");
        }
        let bad = SuiteInput { every: 0, ..input };
        assert!(run(&bad, &Silent).is_err());
    }
}
