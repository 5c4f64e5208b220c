//! Slice dropout (Hu et al. 2020, §3.2 and Fig. 2): keep a subset of the 180 phi_d slices of a
//! BRDF and fill "each missing slice with its nearest neighbour". Used as a training
//! augmentation (random subsets) and to build the 1/3 and 1/9 inputs of Fig. 2 (regular subsets;
//! "currently, the slices are equally spaced").
//!
//! Nearest is measured circularly in phi_d: phi_d is pi-periodic by reciprocity (MERL stores
//! [0, pi)), so slice 179 (179 degrees) is 1 slice away from slice 0 (180 = 0 degrees). A tie
//! between two kept slices at the same distance goes to the lower phi_d index.

use crate::error::{DataError, Result};
use crate::layout::SLICE_VALUES;
use crate::merl::{cell_coords, cell_index, MerlTable, CELLS, INVALID_VALUE, N_PHI_D, VALUES};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Which phi_d slices are kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SliceSelection {
    /// Every n-th slice starting at slice 0: `Every(3)` keeps 60 slices (the "1/3" input of
    /// Fig. 2), `Every(9)` keeps 20 ("1/9"), `Every(1)` keeps all. n is in 1..=180.
    Every(usize),
    /// A seeded uniformly random subset of `keep` distinct slices, 1..=180.
    Random { keep: usize },
}

impl SliceSelection {
    /// Checks the parameter's range.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Self::Every(n) if !(1..=N_PHI_D).contains(&n) => Err(DataError::Invalid(format!(
                "slice selection every:{n}: the step must be in 1..={N_PHI_D}"
            ))),
            Self::Random { keep } if !(1..=N_PHI_D).contains(&keep) => {
                Err(DataError::Invalid(format!(
                    "slice selection random:{keep}: the number of kept slices must be in 1..={N_PHI_D}"
                )))
            }
            _ => Ok(()),
        }
    }
}

impl std::fmt::Display for SliceSelection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Every(n) => write!(f, "every:{n}"),
            Self::Random { keep } => write!(f, "random:{keep}"),
        }
    }
}

impl std::str::FromStr for SliceSelection {
    type Err = DataError;

    /// Parses `every:N` or `random:K` (as written by `Display`), validated.
    fn from_str(s: &str) -> Result<Self> {
        let bad = || {
            DataError::Invalid(format!(
                "slice selection {s:?}: expected every:N (every N-th phi_d slice) or random:K \
                 (K random slices)"
            ))
        };
        let (kind, n) = s.split_once(':').ok_or_else(bad)?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        let selection = match kind.trim() {
            "every" => Self::Every(n),
            "random" => Self::Random { keep: n },
            _ => return Err(bad()),
        };
        selection.validate()?;
        Ok(selection)
    }
}

/// The kept phi_d slice indices, ascending. `seed` only matters for
/// [`SliceSelection::Random`] (ChaCha8, so the same seed gives the same subset everywhere).
///
/// # Panics
/// If the selection is out of range (see [`SliceSelection::validate`]).
pub fn kept_slices(selection: &SliceSelection, seed: u64) -> Vec<usize> {
    if let Err(e) = selection.validate() {
        panic!("{e}");
    }
    match *selection {
        SliceSelection::Every(n) => (0..N_PHI_D).step_by(n).collect(),
        SliceSelection::Random { keep } => {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut kept = rand::seq::index::sample(&mut rng, N_PHI_D, keep).into_vec();
            kept.sort_unstable();
            kept
        }
    }
}

/// Circular distance between two phi_d slice indices (phi_d is pi-periodic).
#[inline]
pub fn slice_distance(a: usize, b: usize) -> usize {
    let d = a.abs_diff(b) % N_PHI_D;
    d.min(N_PHI_D - d)
}

/// The kept slices in the order a missing slice `target` prefers them: by circular distance,
/// ties to the lower index; duplicates removed.
fn preference(target: usize, kept: &[usize]) -> Vec<usize> {
    let mut order = kept.to_vec();
    order.sort_unstable_by_key(|&k| (slice_distance(target, k), k));
    order.dedup();
    order
}

/// For every phi_d slice, the kept slice it is filled from: itself if kept, else the nearest kept
/// slice (circular distance, ties to the lower index).
///
/// # Panics
/// If `kept` is empty or holds an index >= 180.
pub fn fill_sources(kept: &[usize]) -> [usize; N_PHI_D] {
    check_kept(kept);
    let mut sources = [0; N_PHI_D];
    for (target, s) in sources.iter_mut().enumerate() {
        *s = preference(target, kept)[0];
    }
    sources
}

fn check_kept(kept: &[usize]) {
    assert!(!kept.is_empty(), "slice dropout needs at least one kept slice");
    if let Some(k) = kept.iter().find(|&&k| k >= N_PHI_D) {
        panic!("kept slice {k} out of range 0..{N_PHI_D}");
    }
}

/// Fills, in a 540 x 90 x 90 layout ([`crate::layout`]), every phi_d slice not in `kept` with a
/// copy of its nearest kept slice (all 3 colours, invalid entries included, as the paper copies
/// whole image slices); kept slices are unchanged.
///
/// # Panics
/// If `layout` is not [`VALUES`] long, `kept` is empty or holds an index >= 180.
pub fn fill_missing_layout(layout: &mut [f32], kept: &[usize]) {
    assert_eq!(layout.len(), VALUES, "fill_missing_layout needs a 540 x 90 x 90 layout");
    let sources = fill_sources(kept);
    for (target, &source) in sources.iter().enumerate() {
        if source != target {
            layout.copy_within(
                source * SLICE_VALUES..(source + 1) * SLICE_VALUES,
                target * SLICE_VALUES,
            );
        }
    }
}

/// Marker in the per-cell source map: the cell keeps its own value.
const OWN: u16 = u16::MAX;
/// Marker in the per-cell source map: no kept slice has this cell valid; it becomes invalid.
const NONE: u16 = u16::MAX - 1;

impl MerlTable {
    /// The table after slice dropout: values of phi_d slices not in `kept` are replaced by those
    /// of the nearest kept slice (circular distance, ties to the lower index); kept slices are
    /// unchanged.
    ///
    /// Unlike [`fill_missing_layout`], which copies whole image slices, this keeps the table's
    /// validity mask, because validity is a property of the grid, not of the data: invalid
    /// cells stay as they are, and a valid cell whose nearest kept slice is invalid at the same
    /// (theta_h, theta_d) takes the next nearest kept slice where it is valid. If no kept slice
    /// is valid there (only with very few kept slices near phi_d = 0), the cell becomes invalid
    /// ([`INVALID_VALUE`]): there is no measurement to fill it from.
    ///
    /// # Panics
    /// If `kept` is empty or holds an index >= 180.
    pub fn with_kept_slices(&self, kept: &[usize]) -> MerlTable {
        check_kept(kept);
        let preferences: Vec<Vec<usize>> = (0..N_PHI_D).map(|t| preference(t, kept)).collect();
        let source: Vec<u16> = (0..CELLS)
            .into_par_iter()
            .with_min_len(4096)
            .map(|cell| {
                let (h, d, p) = cell_coords(cell);
                if preferences[p][0] == p || !self.is_valid(cell) {
                    return OWN;
                }
                preferences[p]
                    .iter()
                    .find(|&&k| self.is_valid(cell_index(h, d, k)))
                    .map_or(NONE, |&k| k as u16)
            })
            .collect();
        let values = self.values();
        let mut out = values.to_vec();
        out.par_chunks_mut(CELLS).enumerate().for_each(|(c, channel)| {
            let src = &values[c * CELLS..(c + 1) * CELLS];
            for (cell, (v, &s)) in channel.iter_mut().zip(&source).enumerate() {
                match s {
                    OWN => {}
                    NONE => *v = INVALID_VALUE,
                    k => *v = src[cell - cell % N_PHI_D + usize::from(k)],
                }
            }
        });
        match MerlTable::from_values(out) {
            Ok(table) => table,
            // Only copies of this table's finite values: cannot fail.
            Err(e) => unreachable!("{e}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::{to_layout, PLANE};
    use crate::merl::grid::cell_is_valid;

    /// Nearest kept slice by brute force over all kept slices and both ways around the circle.
    fn brute_nearest(target: usize, kept: &[usize]) -> usize {
        let mut best = (usize::MAX, usize::MAX);
        for &k in kept {
            let forward = (k + N_PHI_D - target) % N_PHI_D;
            let backward = (target + N_PHI_D - k) % N_PHI_D;
            let d = forward.min(backward);
            if (d, k) < best {
                best = (d, k);
            }
        }
        best.1
    }

    #[test]
    fn regular_selection_and_known_fills() {
        let every3 = kept_slices(&SliceSelection::Every(3), 0);
        assert_eq!(every3.len(), 60);
        assert_eq!(&every3[..3], &[0, 3, 6]);
        assert_eq!(kept_slices(&SliceSelection::Every(9), 0).len(), 20);
        assert_eq!(kept_slices(&SliceSelection::Every(1), 0), (0..180).collect::<Vec<_>>());
        let s = fill_sources(&kept_slices(&SliceSelection::Every(9), 0));
        assert_eq!(s[4], 0); // 4 from 0, 5 from 9
        assert_eq!(s[5], 9);
        assert_eq!(s[175], 171); // 175: 4 from 171, 5 from 180 = 0
        assert_eq!(s[176], 0); // 176: 5 from 171, 4 from 0 (across pi)
        assert_eq!(s[179], 0);
        // A tie goes to the lower index: 0 and 10 kept, 5 is 5 from both.
        assert_eq!(fill_sources(&[10, 0])[5], 0);
        // Circular tie: 10 and 170 are both 10 away from 0.
        assert_eq!(fill_sources(&[170, 10])[0], 10);
    }

    #[test]
    fn fill_is_nearest_against_brute_force() {
        for seed in 0..20 {
            for keep in [1, 2, 7, 60, 179] {
                let kept = kept_slices(&SliceSelection::Random { keep }, seed);
                let sources = fill_sources(&kept);
                for (t, &s) in sources.iter().enumerate() {
                    assert_eq!(s, brute_nearest(t, &kept), "seed {seed} keep {keep} slice {t}");
                }
            }
        }
    }

    #[test]
    fn random_selection_is_deterministic_and_valid() {
        let sel = SliceSelection::Random { keep: 20 };
        let a = kept_slices(&sel, 42);
        assert_eq!(a, kept_slices(&sel, 42));
        assert_ne!(a, kept_slices(&sel, 43));
        assert_eq!(a.len(), 20);
        assert!(a.windows(2).all(|w| w[0] < w[1]) && a.iter().all(|&k| k < N_PHI_D));
    }

    #[test]
    fn parse_display_and_validation() -> Result<()> {
        assert_eq!("every:3".parse::<SliceSelection>()?, SliceSelection::Every(3));
        assert_eq!("random:20".parse::<SliceSelection>()?, SliceSelection::Random { keep: 20 });
        assert_eq!(SliceSelection::Every(9).to_string(), "every:9");
        for bad in ["every:0", "random:0", "random:181", "every:x", "some:3", "3"] {
            assert!(bad.parse::<SliceSelection>().is_err(), "{bad}");
        }
        Ok(())
    }

    #[test]
    fn layout_fill_copies_nearest_and_keeps_kept() {
        let original: Vec<f32> = (0..VALUES).map(|i| i as f32).collect();
        let kept = kept_slices(&SliceSelection::Random { keep: 13 }, 7);
        let mut filled = original.clone();
        fill_missing_layout(&mut filled, &kept);
        for t in 0..N_PHI_D {
            let s = brute_nearest(t, &kept);
            let got = &filled[t * SLICE_VALUES..(t + 1) * SLICE_VALUES];
            assert_eq!(got, &original[s * SLICE_VALUES..(s + 1) * SLICE_VALUES], "slice {t}");
        }
        assert_eq!(SLICE_VALUES, 3 * PLANE);
    }

    #[test]
    fn table_fill_keeps_mask_and_matches_layout_fill_where_valid() {
        // A table whose value encodes its phi_d index, so copies are easy to trace.
        let table = MerlTable::from_fn(|h, d, p| [p as f32, (h + d) as f32, 1.0 + p as f32]);
        let kept = kept_slices(&SliceSelection::Every(9), 0);
        let filled = table.with_kept_slices(&kept);
        assert_eq!(filled.mask(), table.mask());
        let mut layout = to_layout(table.values());
        fill_missing_layout(&mut layout, &kept);
        let layout_filled = to_layout(filled.values());
        let mut agree = 0usize;
        for cell in 0..CELLS {
            let (h, d, p) = cell_coords(cell);
            if !table.is_valid(cell) {
                continue;
            }
            let nearest = brute_nearest(p, &kept);
            let rgb = filled.rgb(h, d, p);
            if cell_is_valid(h, d, nearest) {
                // The nearest kept slice: same values as the layout fill.
                assert_eq!(rgb, table.rgb(h, d, nearest));
                let i = crate::layout::layout_index(h, d, p, 0);
                assert_eq!(layout_filled[i], layout[i]);
                agree += 1;
            } else {
                // A farther kept slice where the cell is valid.
                let k = rgb[0] as usize;
                assert!(kept.contains(&k) && cell_is_valid(h, d, k));
                assert!(slice_distance(p, k) > slice_distance(p, nearest));
            }
        }
        assert!(agree > CELLS / 2);
    }

    #[test]
    fn table_fill_with_one_slice_invalidates_unfillable_cells() {
        let table = MerlTable::from_fn(|_, _, p| [p as f32; 3]);
        let filled = table.with_kept_slices(&[0]);
        for cell in 0..CELLS {
            let (h, d, _) = cell_coords(cell);
            let v = filled.values()[cell];
            if filled.is_valid(cell) {
                assert_eq!(v, 0.0);
            } else {
                assert!(!cell_is_valid(h, d, 0));
            }
        }
        assert!(filled.valid_cells() < table.valid_cells());
    }
}
