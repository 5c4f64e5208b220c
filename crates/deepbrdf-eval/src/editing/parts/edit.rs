//! The parts edit: a table edited part by part ([`super`]). The table's value at each cell is
//! split among its fitted parts ([`Parts::split`]), and
//!
//! - a roughness edit (every lobe's roughness times `s = alpha' / alpha`, the fitted
//!   attribute's ratio) stretches each lobe's share along theta_h by the stretch edit's rule
//!   ([`crate::editing::stretch`]) with that lobe's own masking at `alpha_k` and `s alpha_k`
//!   (kept within the attribute model's roughness range: a lobe at alpha 1 widens no further),
//!   and leaves the floor, the retro-reflective ridge and the sheen where they were: no energy
//!   moves between parts, and a ridge along theta_d ~ 0 is not stretched as if it were a lobe.
//!   Where the source angles lie beyond the horizon or on cells the table holds invalid, the
//!   lobe takes its fitted value at the new roughness.
//! - a diffuse edit scales the floor's share by the asked ratio of the fitted diffuse albedo,
//!   per channel (an Oren-Nayar floor keeps its shape; a sheen is not diffuse), with the
//!   body's lobes ([`super::PartLobe::is_body`]), which no other edit touches; a channel whose
//!   fitted parts or attributes hold no floor gets the analytic edit's Lambertian change.
//! - a specular edit scales each lobe's share by the asked ratio of the fitted specular albedo
//!   at normal incidence, per channel. A dielectric lobe (its normal colour under
//!   [`METAL_SHARE`] of its grazing one) keeps its grazing colour, as Fresnel's reflectance of
//!   any dielectric goes to 1 at grazing angles; a metal's (or metallic flakes') colour is
//!   scaled at every angle. A channel whose fit or parts hold no specular albedo gets the
//!   analytic edit's ([`crate::editing::analytic_edit`]).
//!
//! A table that is exactly its parts becomes exactly the parts at the new roughness (up to the
//! interpolation between theta_h bins); cells the table holds invalid stay invalid.

use super::{fit_parts, CellAngles, Parts, PartsConfig, FLOOR, LOBE, MAX_LOBES, RETRO, SHEEN};
use crate::attributes::{Attributes, MAX_ROUGHNESS, MIN_ROUGHNESS};
use crate::editing::analytic_edit;
use crate::editing::stretch::Source;
use crate::error::{EvalError, Result};
use deepbrdf_data::merl::grid::ROW;
use deepbrdf_data::merl::{cell_coords, cell_index, MerlTable, CELLS, INVALID_VALUE, N_PHI_D};
use rayon::prelude::*;
use std::f64::consts::PI;

/// A lobe whose normal-incidence colour is at least this share of its grazing colour is a
/// metal's: a dielectric's Fresnel reflectance at normal incidence is at most 0.11 of its
/// grazing one for indices up to 2 (and 0.36 for 4), a conductor's 0.5-0.97.
pub const METAL_SHARE: f64 = 0.25;

/// `table`, whose fitted attributes are `fitted`, edited to `requested` by its parts, fitted
/// first with the default settings: the edited table and the parts.
pub fn fit_and_edit(
    table: &MerlTable,
    fitted: &Attributes,
    requested: &Attributes,
) -> Result<(MerlTable, Parts)> {
    let parts = fit_parts(table, &PartsConfig::default())?.parts;
    Ok((parts_edit(table, &parts, fitted, requested)?, parts))
}

/// `table`, whose parts are `parts` and fitted attributes `fitted`, edited to `requested`
/// (module documentation).
pub fn parts_edit(
    table: &MerlTable,
    parts: &Parts,
    fitted: &Attributes,
    requested: &Attributes,
) -> Result<MerlTable> {
    let (alpha, roughness) = (fitted.roughness, requested.roughness);
    if !(roughness.is_finite() && roughness > 0.0 && alpha.is_finite() && alpha > 0.0) {
        return Err(EvalError::Invalid(format!(
            "editing the parts from roughness {alpha} to {roughness}: both must be finite and positive"
        )));
    }
    let s = roughness / alpha;
    let body: Vec<bool> = parts.lobes.iter().map(|l| l.is_body(&parts.floor)).collect();
    let has_floor = |c: usize| {
        let lobes = parts.lobes.iter().zip(&body).filter(|(_, &b)| b);
        parts.floor.albedo[c] > 0.0
            || lobes.into_iter().any(|(l, _)| l.normal[c] + l.grazing[c] > 0.0)
    };
    // The floor's factor, or where there is no floor to scale, the Lambertian change.
    let floor: [(f64, f64); 3] = std::array::from_fn(|c| {
        let (was, now) = (fitted.diffuse[c], requested.diffuse[c]);
        match was > 0.0 && has_floor(c) {
            true => (now / was, 0.0),
            false => (1.0, (now - was) / PI),
        }
    });
    // Each lobe's specular factor at normal incidence and at grazing angles, per channel.
    let specular: [Option<f64>; 3] = std::array::from_fn(|c| {
        let (was, now) = (fitted.specular[c], requested.specular[c]);
        (was > 0.0 && body.iter().any(|b| !b)).then(|| now / was)
    });
    let lobe_factors: Vec<[(f64, f64); 3]> = parts
        .lobes
        .iter()
        .map(|l| {
            let mean = |x: [f64; 3]| x.iter().sum::<f64>();
            let metal = mean(l.normal) >= METAL_SHARE * mean(l.grazing);
            specular.map(|k| {
                let k = k.unwrap_or(1.0);
                (k, if metal { k } else { 1.0 })
            })
        })
        .collect();
    let split = split(table, parts, &body);
    let values = table.values();
    // One theta_h row (all theta_d, phi_d) of the three channels per task.
    let edited = MerlTable::from_par_rows(|i, mut planes| {
        // Each lobe's own scale: its roughness stays within the attribute model's range.
        let sources: Vec<(f64, Option<Source>)> = parts
            .lobes
            .iter()
            .map(|l| {
                let s = (l.alpha * s).clamp(MIN_ROUGHNESS, MAX_ROUGHNESS) / l.alpha;
                (s, (s != 1.0).then(|| Source::new(i, s)))
            })
            .collect();
        for jk in 0..ROW {
            let (j, k) = (jk / N_PHI_D, jk % N_PHI_D);
            let cell = cell_index(i, j, k);
            let Some(here) = &split[cell] else {
                for (c, plane) in planes.iter_mut().enumerate() {
                    plane[jk] = values[c * CELLS + cell];
                }
                continue;
            };
            let mut value: [f64; 3] = std::array::from_fn(|c| {
                let (factor, add) = floor[c];
                here.floor[c] * factor + add + here.other[c]
            });
            let m = here.grazing;
            for (n, lobe) in parts.lobes.iter().enumerate() {
                if body[n] {
                    continue; // with the floor
                }
                let (s, source) = &sources[n];
                let moved = match source {
                    None => Some(here.lobes[n]),
                    Some(src) => {
                        let g1 = |alpha, cos| lobe.distribution.g1(alpha, cos);
                        src.factor_with(g1, j, k, lobe.alpha, lobe.alpha * s)
                    }
                    .and_then(|f| {
                        let (lo, hi, w) = src.bins;
                        let at = |i| split[cell_index(i, j, k)].as_ref().map(|p| p.lobes[n]);
                        let v = match (at(lo), at(hi)) {
                            (Some(a), Some(b)) => std::array::from_fn(|c| a[c] + w * (b[c] - a[c])),
                            (Some(a), None) | (None, Some(a)) => a,
                            (None, None) => return None,
                        };
                        Some(v.map(|x| x * f))
                    }),
                };
                let moved = moved.unwrap_or_else(|| {
                    let a = CellAngles::of(i, j, k).expect("a split cell is above the horizon");
                    lobe.value_at(lobe.alpha * s, &a)
                });
                for c in 0..3 {
                    let (kn, kg) = lobe_factors[n][c];
                    let (wn, wg) = (lobe.normal[c] * (1.0 - m), lobe.grazing[c] * m);
                    let factor = match wn + wg > 0.0 {
                        true => (wn * kn + wg * kg) / (wn + wg),
                        false => kn,
                    };
                    value[c] += moved[c] * factor;
                }
            }
            for (c, plane) in planes.iter_mut().enumerate() {
                let t = values[c * CELLS + cell];
                plane[jk] = if t < 0.0 { INVALID_VALUE } else { value[c].max(0.0) as f32 };
            }
        }
    })
    .map_err(|e| EvalError::Invalid(format!("editing the parts: the edited table: {e}")))?;
    // The channels the parts could not edit, analytically.
    let between = Attributes {
        specular: std::array::from_fn(|c| match specular[c] {
            Some(_) => requested.specular[c],
            None => fitted.specular[c],
        }),
        ..*requested
    };
    analytic_edit(&edited, &between, requested)
}

/// One cell's table value split among the parts.
struct Split {
    floor: [f64; 3],
    /// The ridge's and the sheen's shares together: they stay where they are.
    other: [f64; 3],
    /// Each lobe's share (the first `parts.lobes.len()`).
    lobes: [[f64; 3]; MAX_LOBES],
    /// The cell's Schlick weight `(1 - cos theta_d)^5`.
    grazing: f64,
}

/// Every cell's split: None where a channel is invalid or the cell lies below the horizon. The
/// body's lobes (`body`) go with the floor.
fn split(table: &MerlTable, parts: &Parts, body: &[bool]) -> Vec<Option<Split>> {
    let values = table.values();
    (0..CELLS)
        .into_par_iter()
        .map(|cell| {
            let t: [f64; 3] = std::array::from_fn(|c| f64::from(values[c * CELLS + cell]));
            if t.iter().any(|&v| v < 0.0) {
                return None;
            }
            let (i, j, k) = cell_coords(cell);
            let angles = CellAngles::of(i, j, k)?;
            let split = parts.split(t, &angles);
            let part = |p: usize| split[p];
            let (retro, sheen) = (part(RETRO), part(SHEEN));
            // Where no part has a value, the whole cell stays as it is.
            let unexplained: [f64; 3] =
                std::array::from_fn(|c| match (0..super::PLACES).any(|p| split[p][c] > 0.0) {
                    true => 0.0,
                    false => t[c],
                });
            let floor = (0..parts.lobes.len())
                .filter(|&k| body[k])
                .fold(part(FLOOR), |f, k| std::array::from_fn(|c| f[c] + part(LOBE + k)[c]));
            Some(Split {
                floor,
                other: std::array::from_fn(|c| retro[c] + sheen[c] + unexplained[c]),
                lobes: std::array::from_fn(|k| part(LOBE + k)),
                grazing: angles.grazing(),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::editing::parts::tests::every_part;
    use crate::editing::parts::{fit_parts, PartsConfig};
    use crate::editing::parts::{Distribution, PartLobe};
    use crate::editing::testing::distance;
    use deepbrdf_data::corpus::{sample_family, Family};

    fn attributes(roughness: f64) -> Attributes {
        Attributes { diffuse: [0.3, 0.2, 0.1], specular: [0.04; 3], roughness }
    }

    #[test]
    fn a_table_of_parts_becomes_its_parts_edited() {
        let parts = every_part();
        let table = parts.table();
        for s in [0.5, 2.0] {
            let mut answer = parts.clone();
            answer.lobes.iter_mut().for_each(|l| l.alpha *= s);
            let edited =
                parts_edit(&table, &parts, &attributes(0.1), &attributes(0.1 * s)).unwrap();
            let (d, unedited) =
                (distance(&edited, &answer.table()), distance(&table, &answer.table()));
            assert!(d < 0.02 && d < 0.1 * unedited, "x{s}: {d} (unedited {unedited})");
        }
        // A diffuse edit scales the floor alone, whatever its shape.
        let mut answer = parts.clone();
        answer.floor.albedo = [0.15, 0.1, 0.05];
        let half = Attributes { diffuse: [0.15, 0.1, 0.05], ..attributes(0.1) };
        let edited = parts_edit(&table, &parts, &attributes(0.1), &half).unwrap();
        assert!(distance(&edited, &answer.table()) < 1e-5);
        // A specular edit halves a dielectric lobe's normal colour and keeps its grazing one,
        // and halves a metal's at every angle.
        let mut metal = parts.clone();
        metal.lobes[1].normal = [0.6, 0.5, 0.3];
        for parts in [parts.clone(), metal] {
            let table = parts.table();
            let mut answer = parts.clone();
            for l in &mut answer.lobes {
                let is_metal = l.normal[0] > 0.5;
                l.normal = l.normal.map(|x| x * 0.5);
                if is_metal {
                    l.grazing = l.grazing.map(|x| x * 0.5);
                }
            }
            let half = Attributes { specular: [0.02; 3], ..attributes(0.1) };
            let edited = parts_edit(&table, &parts, &attributes(0.1), &half).unwrap();
            assert!(distance(&edited, &answer.table()) < 1e-5);
        }
        // A red plastic's wide red lobe is its body's: halved with the floor, not stretched.
        let mut plastic = parts.clone();
        plastic.lobes[1] = PartLobe {
            distribution: Distribution::Ggx,
            alpha: 0.9,
            normal: [0.3, 0.05, 0.0],
            grazing: [0.4, 0.0, 0.0],
        };
        assert!(
            plastic.lobes[1].is_body(&plastic.floor) && !plastic.lobes[0].is_body(&plastic.floor)
        );
        let table = plastic.table();
        let mut answer = plastic.clone();
        answer.floor.albedo = [0.15, 0.1, 0.05];
        answer.lobes[1].normal = [0.15, 0.025, 0.0];
        answer.lobes[1].grazing = [0.2, 0.0, 0.0];
        let edited = parts_edit(&table, &plastic, &attributes(0.1), &half).unwrap();
        assert!(distance(&edited, &answer.table()) < 1e-5);
        let mut answer = plastic.clone();
        answer.lobes[0].alpha *= 2.0;
        let wider = parts_edit(&table, &plastic, &attributes(0.1), &attributes(0.2)).unwrap();
        assert!(distance(&wider, &answer.table()) < 0.02);
        // No edit, no change; bad roughness refused.
        let same = parts_edit(&table, &parts, &attributes(0.1), &attributes(0.1)).unwrap();
        assert!(distance(&same, &table) < 1e-6);
        let e = parts_edit(&table, &parts, &attributes(0.1), &attributes(f64::NAN)).unwrap_err();
        assert!(e.to_string().contains("roughness"), "{e}");
    }

    /// Fitted parts, not the truth: a retro-reflective material's lobe widens and narrows
    /// while its ridge stays, and a two-lobe material's lobes both change, each near the answer.
    #[test]
    fn fitted_parts_edit_layered_materials_towards_the_answer() {
        for (family, index) in [(Family::RetroReflective, 2), (Family::TwoLobe, 0)] {
            let m = sample_family(family, 5, index);
            let table = m.table().unwrap();
            let parts = fit_parts(&table, &PartsConfig::default()).unwrap().parts;
            let fitted = attributes(m.attributes().roughness);
            for s in [0.5, 2.0] {
                let answer = m.roughness_scaled(s);
                // The scale reached where the corpus clamps the roughness.
                let s = answer.attributes().roughness / m.attributes().roughness;
                let answer = answer.table().unwrap();
                let requested = Attributes { roughness: fitted.roughness * s, ..fitted };
                let edited = parts_edit(&table, &parts, &fitted, &requested).unwrap();
                let (d, unedited) = (distance(&edited, &answer), distance(&table, &answer));
                assert!(d < 0.35 * unedited, "{family} x{s}: {d} (unedited {unedited})");
            }
        }
    }

    /// No roughness edit of a generated material (each reflecting at most all the light) makes
    /// one that reflects more than all of it, at normal to grazing incidence.
    #[test]
    fn edits_of_generated_materials_keep_their_energy_below_one() {
        use deepbrdf_data::albedo::directional_albedo;
        // The families with a lobe to edit.
        let lobed = [Family::Plastic, Family::Metal, Family::CoatedPaint, Family::TwoLobe];
        for family in lobed.into_iter().chain([Family::RetroReflective]) {
            let m = sample_family(family, 11, 3);
            let table = m.table().unwrap();
            let parts = fit_parts(&table, &PartsConfig::default()).unwrap().parts;
            let fitted = attributes(m.attributes().roughness);
            for s in [0.5, 2.0] {
                let requested = Attributes { roughness: fitted.roughness * s, ..fitted };
                let edited = parts_edit(&table, &parts, &fitted, &requested).unwrap();
                for deg in [0.0f64, 30.0, 60.0, 75.0, 85.0] {
                    let a = directional_albedo(&edited, deg.to_radians());
                    assert!(a.iter().all(|&v| v <= 1.0), "{family} x{s} at {deg} deg: {a:?}");
                }
            }
        }
    }
}
