//! Where a `slice` model's wrong highlights come from: each material's dark hole and tinted
//! centre ([`crate::editing::lobe`]) at every stage of its reconstruction
//! ([`deepbrdf_model::stages`]: the slice basis' projection, the principal-component path, the
//! decoder at the encoder's latent, the refined encoding). The first stage that shows a defect
//! is where it enters.

use crate::editing::lobe::specular_profile;
use crate::editing::{centre_shift, dark_hole, tinted_centre, Lobe};
use crate::error::{EvalError, Result};
use deepbrdf_data::merl::CELLS;
use deepbrdf_data::MerlTable;
use deepbrdf_model::stages::{stages, STAGES};
use deepbrdf_model::DeepBrdf;
use std::fmt::Write as _;

/// One material's highlight at one stage.
#[derive(Clone, Debug, PartialEq)]
pub struct StageHighlight {
    pub material: String,
    /// One of [`STAGES`].
    pub stage: &'static str,
    /// A dark centre the original has not ([`dark_hole`]).
    pub dark_hole: bool,
    /// The centre's colour moved ([`tinted_centre`]).
    pub tinted: bool,
    /// The lobe at theta_h ~ 0 over its maximum within 15 deg (the original's in
    /// `original_centre`): below 0.6 is a dark centre.
    pub centre_ratio: f64,
    pub original_centre: f64,
    /// The original's lobe peak over its diffuse floor (how visible its highlight is).
    pub original_contrast: f64,
    /// How far the centre's chromaticity moved ([`centre_shift`]).
    pub shift: f64,
}

fn centre_ratio(l: &Lobe) -> f64 {
    l.centre / l.near_max
}

/// `table`'s highlight at every stage of `model`. Fails for a model that is not a `slice`
/// network or a table whose lobe cannot be read ([`Lobe::of`]).
pub fn stage_highlights(
    model: &DeepBrdf,
    material: &str,
    table: &MerlTable,
) -> Result<Vec<StageHighlight>> {
    let original = Lobe::of(table)?;
    let stages = stages(model, table).map_err(|e| EvalError::method(super::NAME, e))?;
    STAGES
        .iter()
        .zip(stages.tables())
        .map(|(&stage, recon)| {
            let lobe = Lobe::of(recon)?;
            Ok(StageHighlight {
                material: material.to_string(),
                stage,
                dark_hole: dark_hole(&original, &lobe),
                tinted: tinted_centre(&original, &lobe),
                centre_ratio: centre_ratio(&lobe),
                original_centre: centre_ratio(&original),
                original_contrast: original.peak / original.floor,
                shift: centre_shift(&original, &lobe),
            })
        })
        .collect()
}

/// Per stage: how many materials have a dark hole, a tinted centre, either; then the materials
/// with a defect at the model's own encoding (`refined`), with the stage where it first shows.
pub fn stage_summary(rows: &[StageHighlight]) -> String {
    let materials = rows.iter().filter(|r| r.stage == STAGES[0]).count();
    let mut s = format!(
        "| stage | dark holes | tinted centres | either (of {materials}) |\n|---|---:|---:|---:|\n"
    );
    for stage in STAGES {
        let at: Vec<&StageHighlight> = rows.iter().filter(|r| r.stage == stage).collect();
        let holes = at.iter().filter(|r| r.dark_hole).count();
        let tints = at.iter().filter(|r| r.tinted).count();
        let either = at.iter().filter(|r| r.dark_hole || r.tinted).count();
        let _ = writeln!(s, "| {stage} | {holes} | {tints} | {either} |");
    }
    let last = STAGES[STAGES.len() - 1];
    let wrong: Vec<&StageHighlight> =
        rows.iter().filter(|r| r.stage == last && (r.dark_hole || r.tinted)).collect();
    if !wrong.is_empty() {
        let _ = writeln!(
            s,
            "\n| material | defect | first stage | centre / max (original) | colour shift | original peak / floor |\n|---|---|---|---:|---:|---:|"
        );
    }
    for r in wrong {
        let first = rows
            .iter()
            .find(|x| x.material == r.material && (x.dark_hole || x.tinted))
            .map_or(last, |x| x.stage);
        let defect = match (r.dark_hole, r.tinted) {
            (true, true) => "dark, tinted",
            (true, false) => "dark",
            _ => "tinted",
        };
        let _ = writeln!(
            s,
            "| {} | {defect} | {first} | {:.2} ({:.2}) | {:.3} | {:.3} |",
            r.material, r.centre_ratio, r.original_centre, r.shift, r.original_contrast
        );
    }
    s
}

/// The theta_h samples [`stage_profiles`] prints: the first twelve (0 to 1.3 deg, where the
/// centre of a highlight is), then a few out to 40 deg.
pub const PROFILE_ROWS: [usize; 19] =
    [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 15, 20, 25, 30, 36, 45, 60];

/// `table`'s specular profile ([`specular_profile`]: luminance over theta_d < 15 deg, by
/// theta_h) beside the model's eq. (1) reference and each stage's, at [`PROFILE_ROWS`], as a
/// markdown table: where the reference peaks above a material, the material's highlight is a
/// dip in the mapped space, and a stage's error there is multiplied by the reference.
pub fn stage_profiles(model: &DeepBrdf, table: &MerlTable) -> Result<String> {
    let stages = stages(model, table).map_err(|e| EvalError::method(super::NAME, e))?;
    // The reference on the original's valid cells.
    let mut reference = model.reference().values().to_vec();
    for cell in (0..CELLS).filter(|&c| !table.is_valid(c)) {
        for c in 0..3 {
            reference[c * CELLS + cell] = -1.0;
        }
    }
    let reference = MerlTable::from_values(reference)?;
    let mut columns = vec![("eq. (1) reference", &reference), ("original", table)];
    columns.extend(STAGES.iter().copied().zip(stages.tables()));
    let profiles = columns.iter().map(|(_, t)| specular_profile(t)).collect::<Result<Vec<_>>>()?;
    let mut s = String::from("| theta_h bin | deg |");
    for (name, _) in &columns {
        let _ = write!(s, " {name} |");
    }
    s.push_str("\n|---:|---:|");
    s.push_str(&"---:|".repeat(columns.len()));
    s.push('\n');
    for &row in &PROFILE_ROWS {
        let Some(deg) = profiles[1].iter().find(|p| p.theta_h == row).map(|p| p.theta_h_deg) else {
            continue;
        };
        let _ = write!(s, "| {row} | {deg:.2} |");
        for profile in &profiles {
            match profile.iter().find(|p| p.theta_h == row) {
                Some(p) => {
                    let _ = write!(s, " {:.4} |", p.luminance);
                }
                None => s.push_str(" - |"),
            }
        }
        s.push('\n');
    }
    Ok(s)
}
