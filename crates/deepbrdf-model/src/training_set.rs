//! The training data of the autoencoder: BRDFs already mapped with eq. (1) and reordered into
//! the §3.2 layout (540 x 90 x 90), with their validity masks in the same layout.

use std::sync::Arc;

use deepbrdf_data::layout::{mask_layout, to_layout, LAYOUT_VALUES};
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::table_set::TableSet;
use deepbrdf_data::MerlTable;
use rayon::prelude::*;
use sha2::{Digest, Sha256};

use crate::error::{ModelError, Result};
use crate::streamed::StreamedTables;

/// Named BRDFs in the mapped §3.2 layout, ready to batch.
///
/// Masks are shared between materials whose masks are equal (the MERL grid's horizon makes
/// them all equal in practice), so a set of 100 BRDFs holds 100 layouts and one mask.
#[derive(Debug, Clone)]
pub struct TrainingSet {
    label: String,
    names: Vec<String>,
    inputs: Vec<Vec<f32>>,
    masks: Vec<Arc<Vec<f32>>>,
    valid: Vec<f64>,
    /// The eq. (1) reference in layout order, for a set built from tables (augmentation maps
    /// through it, [`crate::autoencoder::slice::augmentation`]).
    reference: Option<Arc<Vec<f32>>>,
    /// BRDFs streamed beside the held ones ([`StreamedTables`]; trained by the `slice`
    /// network, which keeps their coefficients only).
    streamed: Option<Arc<StreamedTables>>,
}

impl TrainingSet {
    /// Builds a set from mapped layouts (`540 * 90 * 90` values each, invalid cells 0) and
    /// their masks in layout order (1.0 valid, 0.0 invalid). `label` names the data source
    /// (it is recorded in the model's provenance).
    pub fn from_layouts(
        label: impl Into<String>,
        names: Vec<String>,
        inputs: Vec<Vec<f32>>,
        masks: Vec<Vec<f32>>,
    ) -> Result<Self> {
        let mut shared: Vec<Arc<Vec<f32>>> = Vec::new();
        let masks = masks
            .into_iter()
            .map(|mask| {
                let existing = shared.iter().find(|m| m.as_slice() == mask.as_slice()).cloned();
                existing.unwrap_or_else(|| {
                    let m = Arc::new(mask);
                    shared.push(m.clone());
                    m
                })
            })
            .collect();
        Self::from_parts(label.into(), names, inputs, masks, None)
    }

    fn from_parts(
        label: String,
        names: Vec<String>,
        inputs: Vec<Vec<f32>>,
        masks: Vec<Arc<Vec<f32>>>,
        reference: Option<Arc<Vec<f32>>>,
    ) -> Result<Self> {
        if names.is_empty() {
            return Err(ModelError::Invalid("a training set needs at least one BRDF".into()));
        }
        if names.len() != inputs.len() || names.len() != masks.len() {
            return Err(ModelError::Invalid(format!(
                "{} names, {} layouts and {} masks: the counts must agree",
                names.len(),
                inputs.len(),
                masks.len()
            )));
        }
        for (i, (input, mask)) in inputs.iter().zip(&masks).enumerate() {
            let name = &names[i];
            if input.len() != LAYOUT_VALUES || mask.len() != LAYOUT_VALUES {
                return Err(ModelError::Invalid(format!(
                    "{name}: a layout has {LAYOUT_VALUES} values, got {} values and {} mask entries",
                    input.len(),
                    mask.len()
                )));
            }
            if let Some(j) = input.iter().position(|v| !v.is_finite()) {
                return Err(ModelError::Invalid(format!("{name}: mapped value {j} is not finite")));
            }
            let checked = masks[..i].iter().any(|m| Arc::ptr_eq(m, mask));
            if let Some(j) = mask.iter().position(|&m| !checked && m != 0.0 && m != 1.0) {
                return Err(ModelError::Invalid(format!(
                    "{name}: mask entry {j} is {} (must be 0 or 1)",
                    mask[j]
                )));
            }
        }
        let mut valid = Vec::with_capacity(masks.len());
        for (i, mask) in masks.iter().enumerate() {
            match (0..i).find(|&j| Arc::ptr_eq(&masks[j], mask)) {
                Some(j) => valid.push(valid[j]),
                None => valid.push(mask.iter().map(|&m| f64::from(m)).sum()),
            }
        }
        Ok(Self { label, names, inputs, masks, valid, reference, streamed: None })
    }

    /// Maps `tables` with eq. (1) relative to `reference` and reorders them into the §3.2
    /// layout, in parallel. `names[i]` names `tables[i]`.
    pub fn from_tables(
        label: impl Into<String>,
        names: &[String],
        tables: &[&MerlTable],
        reference: &MedianReference,
    ) -> Result<Self> {
        let tables = tables.to_vec();
        let indices: Vec<usize> = (0..tables.len()).collect();
        Self::from_table_set(label, names, &tables, &indices, reference)
    }

    /// [`TrainingSet::from_tables`] for tables `indices` of `set`, read one at a time (in
    /// parallel), each let go once mapped: a streamed set is never all in memory.
    pub fn from_table_set(
        label: impl Into<String>,
        names: &[String],
        set: &dyn TableSet,
        indices: &[usize],
        reference: &MedianReference,
    ) -> Result<Self> {
        if names.len() != indices.len() {
            return Err(ModelError::Invalid(format!(
                "{} names for {} tables",
                names.len(),
                indices.len()
            )));
        }
        let mapped = indices
            .par_iter()
            .with_max_len(1)
            .map(|&i| {
                let t = set.table(i)?;
                Ok((to_layout(&reference.map(&t)), t.mask()))
            })
            .collect::<Result<Vec<_>>>()?;
        let (inputs, cells): (Vec<Vec<f32>>, Vec<Vec<bool>>) = mapped.into_iter().unzip();
        // Masks are built once per distinct validity pattern.
        let mut unique: Vec<(Vec<bool>, Arc<Vec<f32>>)> = Vec::new();
        let masks = cells
            .into_iter()
            .map(|cells| match unique.iter().find(|(c, _)| *c == cells) {
                Some((_, m)) => m.clone(),
                None => {
                    let m = Arc::new(mask_layout(&cells));
                    unique.push((cells, m.clone()));
                    m
                }
            })
            .collect();
        let reference = Some(Arc::new(to_layout(reference.values())));
        Self::from_parts(label.into(), names.to_vec(), inputs, masks, reference)
    }

    /// The eq. (1) reference the set was mapped with, in layout order (sets built from
    /// tables only).
    pub fn reference_layout(&self) -> Option<&[f32]> {
        self.reference.as_deref().map(Vec::as_slice)
    }

    /// The set with `streamed` BRDFs beside its own (they need the set's eq. (1) reference:
    /// a set built from tables), its label extended with the stream's.
    pub fn with_streamed(mut self, streamed: StreamedTables) -> Result<Self> {
        if self.reference.is_none() {
            return Err(ModelError::Invalid(format!(
                "{}: streamed BRDFs need the eq. (1) reference of a set built from tables",
                self.label
            )));
        }
        self.label = format!("{}+{}", self.label, streamed.label());
        self.streamed = Some(Arc::new(streamed));
        Ok(self)
    }

    /// The BRDFs streamed beside the set's own, if any.
    pub fn streamed(&self) -> Option<&StreamedTables> {
        self.streamed.as_deref()
    }

    /// The data source's label.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The BRDFs' names.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Number of BRDFs.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the set is empty (never, by construction).
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The mapped layout of BRDF `i` (invalid cells 0).
    pub fn input(&self, i: usize) -> &[f32] {
        &self.inputs[i]
    }

    /// The layout mask of BRDF `i`.
    pub fn mask(&self, i: usize) -> &[f32] {
        &self.masks[i]
    }

    /// The number of valid values of BRDF `i` (the sum of its mask).
    pub fn valid_values(&self, i: usize) -> f64 {
        self.valid[i]
    }

    /// Per-value mean over the BRDFs valid there (0 where none is): the offset of the CPU
    /// preset, and the prediction a network with zero output makes.
    pub fn mean(&self) -> Vec<f32> {
        let mut sum = vec![0f64; LAYOUT_VALUES];
        let mut count = vec![0u32; LAYOUT_VALUES];
        for (input, mask) in self.inputs.iter().zip(&self.masks) {
            for ((s, c), (&x, &m)) in
                sum.iter_mut().zip(count.iter_mut()).zip(input.iter().zip(mask.iter()))
            {
                if m != 0.0 {
                    *s += f64::from(x);
                    *c += 1;
                }
            }
        }
        sum.iter()
            .zip(&count)
            .map(|(&s, &c)| if c == 0 { 0.0 } else { (s / f64::from(c)) as f32 })
            .collect()
    }

    /// The per-value spread of the set (standard deviation over the BRDFs valid there, in
    /// layout order), floored at a tenth of its root mean square over the valid values so
    /// that no value is divided by almost nothing; 1 where no BRDF is valid.
    pub fn spread(&self) -> Vec<f32> {
        let mean = self.mean();
        let mut sum = vec![0f64; LAYOUT_VALUES];
        let mut count = vec![0u32; LAYOUT_VALUES];
        for (input, mask) in self.inputs.iter().zip(&self.masks) {
            for (i, (&x, &m)) in input.iter().zip(mask.iter()).enumerate() {
                if m != 0.0 {
                    sum[i] += (f64::from(x) - f64::from(mean[i])).powi(2);
                    count[i] += 1;
                }
            }
        }
        let variance: Vec<Option<f64>> =
            sum.iter().zip(&count).map(|(&s, &c)| (c > 0).then(|| s / f64::from(c))).collect();
        let valid = variance.iter().flatten().count().max(1);
        let floor = 0.1 * (variance.iter().flatten().sum::<f64>() / valid as f64).sqrt();
        let floor = if floor > 0.0 { floor } else { 1.0 };
        variance.iter().map(|v| v.map_or(1.0, |v| v.sqrt().max(floor)) as f32).collect()
    }

    /// A short digest of the set (label, names and a strided sample of values and masks), so
    /// a resumed run can check it sees the same data.
    pub fn fingerprint(&self) -> String {
        let mut hasher = Sha256::new();
        hasher.update(self.label.as_bytes());
        if let Some(streamed) = &self.streamed {
            hasher.update(streamed.identity().as_bytes());
        }
        for (i, name) in self.names.iter().enumerate() {
            hasher.update((name.len() as u64).to_le_bytes());
            hasher.update(name.as_bytes());
            for j in (i % 97..LAYOUT_VALUES).step_by(97) {
                hasher.update(self.inputs[i][j].to_le_bytes());
                hasher.update(self.masks[i][j].to_le_bytes());
            }
        }
        hex::encode(&hasher.finalize()[..16])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layout(v: f32) -> Vec<f32> {
        vec![v; LAYOUT_VALUES]
    }

    #[test]
    fn masks_are_shared_and_the_mean_skips_invalid_values() {
        let mut mask_a = layout(1.0);
        mask_a[0] = 0.0;
        let set = TrainingSet::from_layouts(
            "test",
            vec!["a".into(), "b".into(), "c".into()],
            vec![layout(1.0), layout(2.0), layout(6.0)],
            vec![mask_a.clone(), layout(1.0), mask_a],
        )
        .unwrap();
        assert!(Arc::ptr_eq(&set.masks[0], &set.masks[2]));
        assert!(!Arc::ptr_eq(&set.masks[0], &set.masks[1]));
        let mean = set.mean();
        assert_eq!(mean[0], 2.0); // only "b" is valid at value 0
        assert_eq!(mean[1], 3.0); // (1 + 2 + 6) / 3
    }

    #[test]
    fn the_spread_is_the_deviation_over_valid_brdfs_floored() {
        // Value 0: only "b" valid (spread 0, floored at a tenth of the RMS spread); value 2:
        // no BRDF valid (1); every other value: 1, 3, 5 (spread sqrt(8/3)).
        let mut mask_ac = layout(1.0);
        mask_ac[0] = 0.0;
        mask_ac[2] = 0.0;
        let mut mask_b = layout(1.0);
        mask_b[2] = 0.0;
        let set = TrainingSet::from_layouts(
            "test",
            vec!["a".into(), "b".into(), "c".into()],
            vec![layout(1.0), layout(3.0), layout(5.0)],
            vec![mask_ac.clone(), mask_b, mask_ac],
        )
        .unwrap();
        let spread = set.spread();
        let full = (8.0f64 / 3.0).sqrt();
        assert!((f64::from(spread[1]) - full).abs() < 1e-6, "{}", spread[1]);
        assert_eq!(spread[2], 1.0);
        assert!((f64::from(spread[0]) - 0.1 * full).abs() < 1e-5, "{}", spread[0]);
    }

    #[test]
    fn bad_layouts_are_rejected_with_the_name() {
        let err =
            TrainingSet::from_layouts("t", vec!["x".into()], vec![vec![0.0; 3]], vec![layout(1.0)])
                .unwrap_err()
                .to_string();
        assert!(err.contains("x:"), "{err}");
        let mut nan = layout(0.0);
        nan[5] = f32::NAN;
        assert!(
            TrainingSet::from_layouts("t", vec!["x".into()], vec![nan], vec![layout(1.0)]).is_err()
        );
        assert!(TrainingSet::from_layouts("t", vec![], vec![], vec![]).is_err());
        assert!(TrainingSet::from_layouts(
            "t",
            vec!["x".into()],
            vec![layout(0.0)],
            vec![layout(0.5)]
        )
        .is_err());
    }

    #[test]
    fn the_fingerprint_sees_values_and_names() {
        let make = |name: &str, v: f32| {
            TrainingSet::from_layouts("t", vec![name.into()], vec![layout(v)], vec![layout(1.0)])
                .unwrap()
        };
        assert_eq!(make("a", 1.0).fingerprint(), make("a", 1.0).fingerprint());
        assert_ne!(make("a", 1.0).fingerprint(), make("b", 1.0).fingerprint());
        assert_ne!(make("a", 1.0).fingerprint(), make("a", 1.5).fingerprint());
    }
}
