//! The network input of one BRDF (Hu et al. 2020, §3.1-3.2): the table mapped with eq. (1)
//! against a per-cell median reference, reordered into the 540 x 90 x 90 layout, with its
//! validity mask in the same layout (1 on valid cells, 0 elsewhere; invalid cells of the input
//! are 0). The one routine from a table to what the autoencoder reads: training, encoding and the
//! sweep's evaluation all build their inputs here.

use crate::layout::{mask_layout, to_layout};
use crate::mapping::MedianReference;
use crate::merl::MerlTable;

/// Eq. (1) of `table` under `reference` in the §3.2 layout, and the table's mask in that
/// layout: `(input, mask)`, each [`crate::layout::LAYOUT_VALUES`] long.
pub fn mapped_layout(table: &MerlTable, reference: &MedianReference) -> (Vec<f32>, Vec<f32>) {
    (to_layout(&reference.map(table)), mask_layout(&table.mask()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::{layout_index, LAYOUT_VALUES};
    use crate::mapping::log_relative;
    use crate::merl::{cell_index, CELLS, VALUES};

    #[test]
    fn input_is_eq1_in_the_layout_and_zero_on_invalid_cells() {
        let table = MerlTable::from_fn(|h, d, p| {
            let base = 0.01 + (h * 7 + d * 3 + p) as f32 * 1e-4;
            [base, 2.0 * base, 0.5 * base]
        });
        let reference = MedianReference::from_values(vec![0.05; VALUES]).expect("reference");
        let (input, mask) = mapped_layout(&table, &reference);
        assert_eq!((input.len(), mask.len()), (LAYOUT_VALUES, LAYOUT_VALUES));
        let mut checked = 0;
        for (h, d, p) in [(0, 0, 0), (10, 20, 30), (45, 60, 179), (89, 89, 90), (80, 85, 0)] {
            let cell = cell_index(h, d, p);
            for rgb in 0..3 {
                let at = layout_index(h, d, p, rgb);
                if table.is_valid(cell) {
                    let rho = f64::from(table.values()[rgb * CELLS + cell]);
                    let want = log_relative(rho, f64::from(0.05f32)) as f32;
                    assert_eq!(input[at], want, "{h} {d} {p}");
                    assert_eq!(mask[at], 1.0);
                    checked += 1;
                } else {
                    assert_eq!((input[at], mask[at]), (0.0, 0.0), "invalid cell {h} {d} {p}");
                }
            }
        }
        assert!(checked >= 9, "most probe cells are valid");
    }
}
