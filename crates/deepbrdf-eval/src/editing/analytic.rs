//! The analytic edit: the baseline an edit through a learned representation has to beat. It
//! needs no network: the table's fitted analytic model (the Lambertian + GGX model of the 7
//! [`Attributes`], §5.1) is replaced by the same model at the requested attributes, and what
//! the model does not explain (a second lobe, a sheen, the measurement's own shape) is kept:
//!
//! `T' = T - M_a + M_a'` where the table is above its model (`T >= M_a`: an additive residual),
//! `T' = M_a' T / M_a` where it is below (a fitted lobe brighter or wider than the measured one:
//! the new model scaled by the same shortfall).
//!
//! The two agree at `T = M_a`, and `T'` is never negative: subtracting an overshooting lobe
//! and clamping at 0 leaves a dark hole at the highlight once the new lobe is wider (roughness
//! up), which the scaled branch does not. An identity edit returns the table unchanged; a table
//! that is exactly the model at `a` becomes exactly the model at `a'`. Cells the table holds
//! invalid stay invalid.

use crate::attributes::Attributes;
use crate::error::{EvalError, Result};
use deepbrdf_data::merl::INVALID_VALUE;
use deepbrdf_data::MerlTable;

/// `table` edited from its fitted attributes `fitted` to `requested` (see the module's
/// documentation).
pub fn analytic_edit(
    table: &MerlTable,
    fitted: &Attributes,
    requested: &Attributes,
) -> Result<MerlTable> {
    if fitted == requested {
        return Ok(table.clone());
    }
    carry_edit(table, &fitted.table(), &requested.table())
}

/// The change from the model `before` to the model `after` carried onto `table` by the rule of
/// the module's documentation: `T - M + M'` where `T >= M`, `M' T / M` below. The analytic edit
/// takes the fitted analytic model at the two attribute vectors; the transfer edit
/// ([`crate::editing::Space::transfer`]) a representation's decoded tables.
pub fn carry_edit(table: &MerlTable, before: &MerlTable, after: &MerlTable) -> Result<MerlTable> {
    let values: Vec<f32> = table
        .values()
        .iter()
        .zip(before.values().iter().zip(after.values()))
        .map(|(&t, (&m, &m_new))| match t < 0.0 || m < 0.0 || m_new < 0.0 {
            true if t < 0.0 => INVALID_VALUE,
            true => t,
            false => edit_value(f64::from(t), f64::from(m), f64::from(m_new)) as f32,
        })
        .collect();
    MerlTable::from_values(values)
        .map_err(|e| EvalError::Invalid(format!("carrying an edit: the edited table: {e}")))
}

/// One value of the edit: table `t`, model `m` before and `m_new` after (all >= 0).
fn edit_value(t: f64, m: f64, m_new: f64) -> f64 {
    match t >= m {
        true => t - m + m_new,
        false => m_new * t / m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::merl::{cell_index, CELLS};

    fn attributes(roughness: f64) -> Attributes {
        Attributes { diffuse: [0.3, 0.2, 0.1], specular: [0.05, 0.05, 0.05], roughness }
    }

    #[test]
    fn a_model_table_becomes_the_edited_model() {
        let (a, b) = (attributes(0.1), attributes(0.2));
        let edited = analytic_edit(&a.table(), &a, &b).unwrap();
        let answer = b.table();
        for (x, y) in edited.values().iter().zip(answer.values()) {
            assert!((x - y).abs() <= 1e-5 * y.abs().max(1.0), "{x} vs {y}");
        }
        assert_eq!(analytic_edit(&answer, &b, &b).unwrap().values(), answer.values());
    }

    #[test]
    fn the_residual_is_kept_and_invalid_cells_stay_invalid() {
        let (a, b) = (attributes(0.1), attributes(0.05));
        let mut table = a.table();
        // A constant residual the model does not explain, and one invalid cell.
        table.values_mut().iter_mut().filter(|v| **v >= 0.0).for_each(|v| *v += 0.25);
        let far = cell_index(0, 40, 0);
        table.values_mut()[far] = INVALID_VALUE;
        let edited = analytic_edit(&table, &a, &b).unwrap();
        let answer = b.table();
        assert_eq!(edited.values()[far], INVALID_VALUE);
        for c in (0..3 * CELLS).step_by(7919).filter(|&c| c != far && answer.values()[c] >= 0.0) {
            let (x, y) = (edited.values()[c], answer.values()[c] + 0.25);
            assert!((x - y).abs() <= 1e-4 * y.max(1.0), "value {c}: {x} vs {y}");
        }
        // Below its model the table's shortfall scales the new model: never negative, and a
        // black table stays black.
        let dark = MerlTable::from_fn(|_, _, _| [0.0; 3]);
        let edited = analytic_edit(&dark, &attributes(0.1), &attributes(0.3)).unwrap();
        assert!(edited.values().iter().all(|&v| v == 0.0 || v == INVALID_VALUE));
        assert_eq!(edit_value(1.0, 4.0, 2.0), 0.5);
        assert_eq!(edit_value(5.0, 4.0, 2.0), 3.0);
        // The branches meet at t = m.
        assert_eq!(edit_value(4.0, 4.0, 2.0), 2.0);
        assert!((edit_value(4.0 - 1e-9, 4.0, 2.0) - 2.0).abs() < 1e-8);
    }

    #[test]
    fn carrying_onto_the_model_itself_gives_the_new_model() {
        let (before, after) = (attributes(0.1).table(), attributes(0.3).table());
        assert_eq!(carry_edit(&before, &before, &after).unwrap().values(), after.values());
        let table = attributes(0.05).table();
        assert_eq!(carry_edit(&table, &before, &before).unwrap().values(), table.values());
    }
}
