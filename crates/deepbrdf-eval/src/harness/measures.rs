//! Error measures between an original table and its reconstruction, each over the cells valid
//! in the original only (invalid cells carry no measurement).

use crate::editing::{dark_hole, tinted_centre, Lobe};
use crate::error::{EvalError, Result};
use deepbrdf_data::mapping::{log_relative, MedianReference};
use deepbrdf_data::merl::{grid, CELLS, VALUES};
use deepbrdf_data::MerlTable;
use rayon::prelude::*;
use std::str::FromStr;

/// A reconstruction error measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Measure {
    /// Mean squared error in the space of the paper's eq. (1),
    /// `ln((rho + eps)/(rho_ref + eps) + 1)`, the reference being the per-value median of the
    /// run's (or fold's) training tables: the space DeepBRDF is trained in, the common yardstick.
    MappedMse,
    /// Root mean square of `(rho - rho_hat) cos(theta_i) cos(theta_o)`, linear reflectance
    /// (1/sr) weighted by the cosines as in Nielsen et al. 2015's mapping.
    CosRmse,
    /// Image-space RelAE (§4, Fig. 4): `sum |I - I_ref| / sum |I_ref|` between renders of the
    /// reconstruction and of the original, the preview sphere under sun and sky
    /// ([`crate::metrics::ImageRelae`] with its default scene). Costs two renders (~0.15 s of
    /// CPU each), so it is opt-in.
    ImageRelae,
    /// 1 where the reconstruction's highlight has a dark centre that the original's has not
    /// ([`crate::editing::dark_hole`]: the specular profile at theta_h ~ 0 below 60% of its
    /// maximum within 15 deg), else 0; summed, the number of materials decoded with a dark dot
    /// at the highlight.
    DarkHole,
    /// 1 where the highlight's centre changed colour ([`crate::editing::tinted_centre`]: its
    /// chromaticity over theta_h bins 0-2, theta_d < 15 deg, moved by more than 0.10), else 0.
    TintedCentre,
}

// All measures, in table order, by their machine names (CSV files, the command line).
deepbrdf_data::named_enum!(Measure {
    MappedMse => "mapped_mse",
    CosRmse => "cos_rmse",
    ImageRelae => "image_relae",
    DarkHole => "dark_hole",
    TintedCentre => "tinted_centre",
});

impl Measure {
    /// The error measures computed on the tables alone (fast; the default).
    pub const TABLE: [Measure; 2] = [Measure::MappedMse, Measure::CosRmse];
    /// The highlight's defects, counted per material.
    pub const HIGHLIGHT: [Measure; 2] = [Measure::DarkHole, Measure::TintedCentre];

    /// Whether the measure is a 0/1 defect whose sum over materials is reported (a count), not
    /// a mean error.
    pub fn counts(self) -> bool {
        matches!(self, Self::DarkHole | Self::TintedCentre)
    }

    /// Whether the measure renders images (not computed by [`Yardstick::measure`]).
    pub fn renders(self) -> bool {
        self == Self::ImageRelae
    }

    /// Human label for plots and tables.
    pub fn label(self) -> &'static str {
        match self {
            Self::MappedMse => "MSE in eq. (1) mapped space",
            Self::CosRmse => "cosine-weighted RMSE (1/sr)",
            Self::ImageRelae => "image-space RelAE (sphere, sun and sky)",
            Self::DarkHole => "materials decoded with a dark hole at the highlight",
            Self::TintedCentre => "materials decoded with a tinted highlight centre",
        }
    }
}

impl FromStr for Measure {
    type Err = EvalError;
    fn from_str(s: &str) -> Result<Self> {
        Self::from_name(s).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|m| m.name()).collect();
            EvalError::Invalid(format!("unknown measure '{s}' ({})", names.join(", ")))
        })
    }
}

/// What the measures compare against: the training median of eq. (1) (and the grid's cosine
/// weights, [`grid::cos_weights`]).
pub struct Yardstick {
    reference: MedianReference,
}

/// One original table prepared for repeated comparisons: its valid cells and their eq. (1)
/// values, computed once.
pub struct Original<'a> {
    table: &'a MerlTable,
    /// Cells valid in the original, increasing.
    cells: Vec<u32>,
    /// Eq. (1) of the original at `cells`, channel-major (`c * cells.len() + m`).
    mapped: Vec<f32>,
    /// The original's specular lobe, read when a highlight measure first asks; `None` where it
    /// cannot be read ([`Lobe::of`]).
    lobe: std::sync::OnceLock<Option<Lobe>>,
}

/// Valid cells per parallel work item.
const CHUNK: usize = 16 * 1024;

impl Yardstick {
    /// The yardstick of a training set: eq. (1)'s reference is their per-value median.
    pub fn from_training(train: &[&MerlTable]) -> Result<Self> {
        Ok(Self::from_reference(MedianReference::from_tables(train)?))
    }

    /// The yardstick of an already computed eq. (1) reference.
    pub fn from_reference(reference: MedianReference) -> Self {
        Self { reference }
    }

    /// The eq. (1) reference (the per-value median of the training tables).
    pub fn reference(&self) -> &MedianReference {
        &self.reference
    }

    /// Prepares `table` for comparisons.
    pub fn original<'a>(&self, table: &'a MerlTable) -> Original<'a> {
        let cells: Vec<u32> = (0..CELLS as u32)
            .into_par_iter()
            .with_min_len(CHUNK)
            .filter(|&c| table.is_valid(c as usize))
            .collect();
        let n = cells.len();
        let (v, r) = (table.values(), self.reference.values());
        let mut mapped = vec![0f32; 3 * n];
        for (c, out) in mapped.chunks_mut(n.max(1)).enumerate() {
            out.par_chunks_mut(CHUNK).zip(cells.par_chunks(CHUNK)).for_each(|(out, cells)| {
                for (o, &cell) in out.iter_mut().zip(cells) {
                    let i = c * CELLS + cell as usize;
                    *o = log_relative(f64::from(v[i]), f64::from(r[i])) as f32;
                }
            });
        }
        Original { table, cells, mapped, lobe: std::sync::OnceLock::new() }
    }

    /// All `measures` of `recon` against `original`, in the given order. A reconstruction that
    /// is invalid (negative) where the original is valid counts as reflectance 0 there.
    pub fn measure(
        &self,
        original: &Original,
        recon: &MerlTable,
        measures: &[Measure],
    ) -> Result<Vec<f64>> {
        if recon.values().len() != VALUES {
            return Err(EvalError::Invalid("reconstruction is not a full table".into()));
        }
        if let Some(m) = measures.iter().find(|m| m.renders()) {
            return Err(EvalError::Invalid(format!(
                "{m} is measured on renders (metrics::ImageRelae), not on tables"
            )));
        }
        let n = original.cells.len();
        if n == 0 {
            return Err(EvalError::Invalid("the original table has no valid cell".into()));
        }
        let want_mapped = measures.contains(&Measure::MappedMse);
        let (a, b, r) = (original.table.values(), recon.values(), self.reference.values());
        let weights = grid::cos_weights();
        // Sums of squared eq. (1) differences and of squared cosine-weighted differences: one
        // partial sum per chunk in parallel, added in chunk order (the same bits for any thread
        // count).
        let parts: Vec<(f64, f64)> = original
            .cells
            .par_chunks(CHUNK)
            .enumerate()
            .map(|(chunk, cells)| {
                let (mut mapped_sum, mut cos_sum) = (0f64, 0f64);
                for (m, &cell) in (chunk * CHUNK..).zip(cells) {
                    let cell = cell as usize;
                    let w = f64::from(weights[cell].max(0.0));
                    for c in 0..3 {
                        let i = c * CELLS + cell;
                        let rho_hat = f64::from(b[i].max(0.0));
                        let d = (f64::from(a[i]) - rho_hat) * w;
                        cos_sum += d * d;
                        if want_mapped {
                            let d = f64::from(original.mapped[c * n + m])
                                - f64::from(log_relative(rho_hat, f64::from(r[i])) as f32);
                            mapped_sum += d * d;
                        }
                    }
                }
                (mapped_sum, cos_sum)
            })
            .collect();
        let (mapped_sum, cos_sum) = parts.iter().fold((0.0, 0.0), |x, y| (x.0 + y.0, x.1 + y.1));
        let count = (3 * n) as f64;
        let defects = match measures.iter().any(|m| m.counts()) {
            true => original
                .lobe
                .get_or_init(|| Lobe::of(original.table).ok())
                .as_ref()
                .map(|o| highlight_defects(o, recon)),
            false => None,
        };
        let flag = |d: Option<(bool, bool)>, pick: fn((bool, bool)) -> bool| {
            d.map_or(f64::NAN, |d| f64::from(u8::from(pick(d))))
        };
        Ok(measures
            .iter()
            .map(|m| match m {
                Measure::MappedMse => mapped_sum / count,
                Measure::CosRmse => (cos_sum / count).sqrt(),
                Measure::ImageRelae => f64::NAN, // rejected above
                Measure::DarkHole => flag(defects, |d| d.0),
                Measure::TintedCentre => flag(defects, |d| d.1),
            })
            .collect())
    }
}

/// (dark hole, tinted centre) of `recon` against the original's lobe; a reconstruction whose
/// lobe cannot be read has both.
fn highlight_defects(original: &Lobe, recon: &MerlTable) -> (bool, bool) {
    match Lobe::of(recon) {
        Ok(lobe) => (dark_hole(original, &lobe), tinted_centre(original, &lobe)),
        Err(_) => (true, true),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::testing::synthetic_table;

    #[test]
    fn measures_match_their_definitions_written_out() {
        let (a, b) = (synthetic_table(0), synthetic_table(3));
        let yardstick = Yardstick::from_training(&[&a, &b, &synthetic_table(5)]).unwrap();
        let original = yardstick.original(&a);
        // The reconstruction loses a few cells (invalid where the original is valid): they count
        // as reflectance 0.
        let mut recon = b.clone();
        let lost = [deepbrdf_data::merl::cell_index(3, 4, 5), 777_777];
        for &cell in &lost {
            assert!(a.is_valid(cell));
            recon.values_mut()[CELLS + cell] = -1.0;
        }
        let got = yardstick.measure(&original, &recon, &Measure::TABLE).unwrap();
        // Independent computation: the reference's own full-table map (eq. 1), all cells.
        let (ma, mut zeroed) = (yardstick.reference().map(&a), recon.values().to_vec());
        for &cell in &lost {
            for c in 0..3 {
                zeroed[c * CELLS + cell] = zeroed[c * CELLS + cell].max(0.0);
            }
        }
        let mb = yardstick.reference().map(&MerlTable::from_values(zeroed.clone()).unwrap());
        let (mut mse, mut cos, mut count) = (0f64, 0f64, 0usize);
        for cell in (0..CELLS).filter(|&c| a.is_valid(c)) {
            let w = grid::cos_product(cell);
            for c in 0..3 {
                let i = c * CELLS + cell;
                mse += (f64::from(ma[i]) - f64::from(mb[i])).powi(2);
                cos += ((f64::from(a.values()[i]) - f64::from(zeroed[i])) * w).powi(2);
                count += 1;
            }
        }
        let (mse, rmse) = (mse / count as f64, (cos / count as f64).sqrt());
        assert!((got[0] - mse).abs() <= 1e-9 * mse, "mapped mse {} vs {mse}", got[0]);
        assert!((got[1] - rmse).abs() <= 1e-6 * rmse, "cos rmse {} vs {rmse}", got[1]);
        // A perfect reconstruction scores 0 on every measure.
        assert_eq!(yardstick.measure(&original, &a, &Measure::TABLE).unwrap(), vec![0.0, 0.0]);
        // Order follows the request.
        let one = yardstick.measure(&original, &recon, &[Measure::CosRmse]).unwrap();
        assert_eq!(one, vec![got[1]]);
    }

    #[test]
    fn a_dark_dot_at_the_highlight_counts_and_the_original_does_not() {
        use deepbrdf_data::ggx::{ggx, Ggx};
        use deepbrdf_data::merl::coords::HalfDiff;
        use deepbrdf_data::testing::tabulate;
        // Lambertian orange + a white GGX lobe; the same with the lobe cut out below `hole`
        // degrees of theta_h.
        let table = |hole: f64, blue: f64| {
            let spec = Ggx { alpha: 0.08, f0: [0.04, 0.04, blue], diffuse: [0.0; 3] };
            tabulate(move |wi, wo| {
                let s = match HalfDiff::from_dirs(wi, wo).theta_h.to_degrees() < hole {
                    true => [0.0; 3],
                    false => ggx(&spec, wi, wo),
                };
                std::array::from_fn(|c| [0.5, 0.3, 0.1][c] / std::f64::consts::PI + s[c])
            })
        };
        let a = table(0.0, 0.04);
        let yardstick = Yardstick::from_training(&[&a]).unwrap();
        let original = yardstick.original(&a);
        let both = Measure::HIGHLIGHT;
        assert_eq!(yardstick.measure(&original, &a, &both).unwrap(), vec![0.0, 0.0]);
        // A dot: dark and, the floor's orange showing through, tinted.
        let dot = yardstick.measure(&original, &table(3.0, 0.04), &both).unwrap();
        assert_eq!(dot, vec![1.0, 1.0]);
        // A blue-free highlight of the same brightness: tinted, not dark.
        let yellow = yardstick.measure(&original, &table(0.0, 0.0), &both).unwrap();
        assert_eq!(yellow, vec![0.0, 1.0]);
        assert!(both.iter().all(|m| m.counts()) && !Measure::TABLE.iter().any(|m| m.counts()));
    }
}
