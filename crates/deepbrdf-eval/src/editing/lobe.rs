//! Measures of a table's specular lobe that see what a person sees in a rendering: where the
//! highlight is, how wide, how bright, of what colour, and whether its centre went dark. They
//! read the table itself, not attributes re-estimated by the Lambertian + GGX fit, which reads a
//! dark hole at the highlight as a wider lobe.
//!
//! The definitions are those of the editing issue that asks for edits that do what they ask:
//!
//! - the **specular profile**: the luminance (Rec. 709) of the mean RGB over the valid cells with
//!   theta_d < 15 deg (all phi_d), one value per theta_h sample that has such a cell;
//! - the **diffuse floor**: the median of the profile over theta_h >= 45 deg;
//! - the **lobe**: the profile minus the floor; its **peak** (the maximum) and where it is; its
//!   **half width at half maximum** (HWHM): from the peak outward (growing theta_h) to the first
//!   crossing below half the peak, interpolated linearly between theta_h samples;
//! - the peak's **colour**: the RGB chromaticity of the lobe at the peak, each channel's profile
//!   minus that channel's floor;
//! - a **dark hole**: the lobe at theta_h ~ 0 (the first sample) below 60% of the lobe's maximum
//!   within theta_h <= 15 deg, where the original's was not;
//! - the **centre's colour**: the RGB chromaticity of the profile's mean over theta_h bins 0-2
//!   (the highlight's centre as a renderer shows it, floor included); a **tinted centre**: a
//!   reconstruction whose centre colour is more than 0.10 (Euclidean, in chromaticity) from the
//!   original's. A dark hole or a tinted centre is a wrong highlight: the decoding issue counts
//!   both;
//! - the **bars** of an edit: roughness x2 widens the HWHM >= 1.4x, roughness x0.5 narrows it to
//!   <= 0.75x, diffuse x0.5 leaves the floor at 0.35-0.65x with the peak within 25% and its
//!   colour within 20%; and no edit leaves a dark hole.

use super::request::{ColourEdit, Edit, ScalarEdit};
use crate::error::{EvalError, Result};
use crate::stats::finite_median;
use deepbrdf_data::merl::grid::{cell_index, theta_d_of, theta_h_of};
use deepbrdf_data::merl::{CELLS, N_PHI_D, N_THETA_D, N_THETA_H};
use deepbrdf_data::MerlTable;
use deepbrdf_render::sky::luminance;

/// The profile averages the cells with theta_d below this (degrees): near the mirror
/// configuration, where a highlight is seen.
pub const PROFILE_MAX_THETA_D_DEG: f64 = 15.0;
/// The diffuse floor is the median of the profile from this theta_h on (degrees).
pub const FLOOR_MIN_THETA_H_DEG: f64 = 45.0;
/// A dark hole: the lobe at theta_h ~ 0 below this fraction of its maximum within
/// [`HOLE_WINDOW_DEG`].
pub const HOLE_FRACTION: f64 = 0.6;
/// The theta_h window (degrees) of the maximum a dark hole is judged against.
pub const HOLE_WINDOW_DEG: f64 = 15.0;
/// The highlight's centre: the theta_h bins below this index.
pub const CENTRE_BINS: usize = 3;
/// A tinted centre: the centre's chromaticity moved by more than this (Euclidean).
pub const TINT_SHIFT: f64 = 0.10;
/// Roughness x2 passes when the HWHM grows by at least this factor.
pub const WIDEN_MIN_RATIO: f64 = 1.4;
/// Roughness x0.5 passes when the HWHM shrinks to at most this factor.
pub const NARROW_MAX_RATIO: f64 = 0.75;
/// Diffuse x0.5 passes when the floor ends in this range of the original's.
pub const DIFFUSE_FLOOR_RATIO: (f64, f64) = (0.35, 0.65);
/// ... and the peak within this relative change ...
pub const DIFFUSE_PEAK_TOLERANCE: f64 = 0.25;
/// ... and the peak's colour within this relative change ([`LobeComparison::colour_shift`]).
pub const DIFFUSE_COLOUR_TOLERANCE: f64 = 0.2;

/// One theta_h sample of the specular profile.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfileSample {
    /// The theta_h index (0..90).
    pub theta_h: usize,
    /// Its angle in degrees (the bin centre, [`theta_h_of`]).
    pub theta_h_deg: f64,
    /// Mean RGB (1/sr) over the valid cells of this theta_h with theta_d <
    /// [`PROFILE_MAX_THETA_D_DEG`].
    pub rgb: [f64; 3],
    /// Luminance of `rgb`.
    pub luminance: f64,
}

/// The specular lobe of a table (see the module's definitions).
#[derive(Clone, Debug, PartialEq)]
pub struct Lobe {
    /// The specular profile, theta_h growing, only samples with a valid cell.
    pub profile: Vec<ProfileSample>,
    /// The diffuse floor: median luminance of the profile for theta_h >= 45 deg.
    pub floor: f64,
    /// The same median per channel.
    pub floor_rgb: [f64; 3],
    /// The lobe's maximum (luminance above the floor; <= 0 when there is no lobe).
    pub peak: f64,
    /// Where the maximum is: index into `profile`.
    pub peak_sample: usize,
    /// theta_h (degrees) of the maximum.
    pub peak_theta_h_deg: f64,
    /// The half width at half maximum (degrees), measured from the peak outward; `None` when
    /// the peak is not above the floor or the lobe never falls below half of it.
    pub hwhm_deg: Option<f64>,
    /// RGB chromaticity (summing to 1) of the lobe at the peak; `None` when the lobe's channels
    /// there do not sum to a positive value.
    pub peak_colour: Option<[f64; 3]>,
    /// The lobe at the first profile sample (theta_h ~ 0).
    pub centre: f64,
    /// The lobe's maximum over the samples with theta_h <= 15 deg.
    pub near_max: f64,
    /// RGB chromaticity of the profile's mean over theta_h bins `0..CENTRE_BINS` (floor
    /// included); `None` when none of those bins has a valid cell or their sum is not positive.
    pub centre_colour: Option<[f64; 3]>,
}

impl Lobe {
    /// Measures the lobe of `table`. Fails when no valid cell has theta_d < 15 deg, none of
    /// those has theta_h >= 45 deg (no floor) or none has theta_h <= 15 deg (no centre).
    pub fn of(table: &MerlTable) -> Result<Self> {
        let profile = specular_profile(table)?;
        let tail: Vec<&ProfileSample> =
            profile.iter().filter(|s| s.theta_h_deg >= FLOOR_MIN_THETA_H_DEG).collect();
        if tail.is_empty() {
            return Err(EvalError::Invalid(format!(
                "no valid cell with theta_h >= {FLOOR_MIN_THETA_H_DEG} deg and theta_d < \
                 {PROFILE_MAX_THETA_D_DEG} deg: the diffuse floor is undefined"
            )));
        }
        if profile[0].theta_h_deg > HOLE_WINDOW_DEG {
            return Err(EvalError::Invalid(format!(
                "no valid cell with theta_h <= {HOLE_WINDOW_DEG} deg and theta_d < \
                 {PROFILE_MAX_THETA_D_DEG} deg: the lobe's centre is undefined"
            )));
        }
        let floor = finite_median(tail.iter().map(|s| s.luminance));
        let floor_rgb: [f64; 3] =
            std::array::from_fn(|c| finite_median(tail.iter().map(|s| s.rgb[c])));
        // Differences within rounding of the floor are no lobe (a flat table has neither a
        // width nor a dark centre).
        let rounding = 1e-9 * floor.abs();
        let lobe: Vec<f64> = profile
            .iter()
            .map(|s| s.luminance - floor)
            .map(|v| if v.abs() <= rounding { 0.0 } else { v })
            .collect();
        let (peak_sample, peak) = lobe
            .iter()
            .copied()
            .enumerate()
            .fold((0, f64::NEG_INFINITY), |best, (i, v)| if v > best.1 { (i, v) } else { best });
        let hwhm_deg = half_width(&profile, &lobe, peak_sample);
        let at_peak: [f64; 3] = std::array::from_fn(|c| profile[peak_sample].rgb[c] - floor_rgb[c]);
        let sum: f64 = at_peak.iter().sum();
        let peak_colour = (sum > 0.0).then(|| at_peak.map(|v| v / sum));
        let near_max = profile
            .iter()
            .zip(&lobe)
            .filter(|(s, _)| s.theta_h_deg <= HOLE_WINDOW_DEG)
            .map(|(_, v)| *v)
            .fold(f64::NEG_INFINITY, f64::max);
        let centre: Vec<&ProfileSample> =
            profile.iter().filter(|s| s.theta_h < CENTRE_BINS).collect();
        let centre_sum: [f64; 3] =
            std::array::from_fn(|c| centre.iter().map(|s| s.rgb[c]).sum::<f64>());
        let total: f64 = centre_sum.iter().sum();
        let centre_colour =
            (total > 0.0 && total.is_finite()).then(|| centre_sum.map(|v| v / total));
        Ok(Self {
            centre_colour,
            floor,
            floor_rgb,
            peak,
            peak_sample,
            peak_theta_h_deg: profile[peak_sample].theta_h_deg,
            hwhm_deg,
            peak_colour,
            centre: lobe[0],
            near_max,
            profile,
        })
    }

    /// Whether the lobe at theta_h ~ 0 is below 60% of its maximum within 15 deg (a dark dot or
    /// a ring where the highlight should be). A table without a lobe (maximum <= 0) has none.
    pub fn has_dark_centre(&self) -> bool {
        self.near_max > 0.0 && self.centre < HOLE_FRACTION * self.near_max
    }
}

/// The specular profile of `table` (see [`ProfileSample`]): theta_h samples without a valid
/// cell at theta_d < 15 deg are left out. Fails when none has one.
pub fn specular_profile(table: &MerlTable) -> Result<Vec<ProfileSample>> {
    let d_max = (0..N_THETA_D)
        .take_while(|&d| theta_d_of(d).to_degrees() < PROFILE_MAX_THETA_D_DEG)
        .count();
    let v = table.values();
    let profile: Vec<ProfileSample> = (0..N_THETA_H)
        .filter_map(|h| {
            let mut sum = [0f64; 3];
            let mut n = 0usize;
            for d in 0..d_max {
                for p in 0..N_PHI_D {
                    let cell = cell_index(h, d, p);
                    if table.is_valid(cell) {
                        for (c, s) in sum.iter_mut().enumerate() {
                            *s += f64::from(v[c * CELLS + cell]);
                        }
                        n += 1;
                    }
                }
            }
            (n > 0).then(|| {
                let rgb = sum.map(|s| s / n as f64);
                ProfileSample {
                    theta_h: h,
                    theta_h_deg: theta_h_of(h).to_degrees(),
                    rgb,
                    luminance: luminance(rgb),
                }
            })
        })
        .collect();
    if profile.is_empty() {
        return Err(EvalError::Invalid(format!(
            "no valid cell with theta_d < {PROFILE_MAX_THETA_D_DEG} deg: the specular profile \
             is undefined"
        )));
    }
    Ok(profile)
}

/// From `lobe[peak]` outward, the theta_h (degrees) of the first crossing below half the peak,
/// linear between samples, minus the peak's theta_h.
fn half_width(profile: &[ProfileSample], lobe: &[f64], peak: usize) -> Option<f64> {
    let half = 0.5 * lobe[peak];
    if half.is_nan() || half <= 0.0 {
        return None;
    }
    (peak + 1..lobe.len()).find(|&i| lobe[i] < half).map(|i| {
        let (a, b) = (profile[i - 1].theta_h_deg, profile[i].theta_h_deg);
        let t = (lobe[i - 1] - half) / (lobe[i - 1] - lobe[i]);
        a + t * (b - a) - profile[peak].theta_h_deg
    })
}

/// How an edited table's lobe compares with the original's. Ratios are edited over original
/// (NaN where either is undefined or the original's is not positive).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeComparison {
    /// Diffuse floor.
    pub floor_ratio: f64,
    /// The lobe's peak.
    pub peak_ratio: f64,
    /// The half width at half maximum.
    pub hwhm_ratio: f64,
    /// `|c_edited - c_original| / |c_original|` of the peaks' chromaticities (Euclidean over
    /// the channels).
    pub colour_shift: f64,
    /// The edited lobe has a dark centre ([`Lobe::has_dark_centre`]) that the original does
    /// not.
    pub dark_hole: bool,
}

fn ratio(edited: f64, original: f64) -> f64 {
    match original > 0.0 && edited.is_finite() {
        true => edited / original,
        false => f64::NAN,
    }
}

/// Compares the lobes (see [`LobeComparison`]).
pub fn compare(original: &Lobe, edited: &Lobe) -> LobeComparison {
    let colour_shift = match (original.peak_colour, edited.peak_colour) {
        (Some(o), Some(e)) => {
            let d: f64 = o.iter().zip(&e).map(|(a, b)| (a - b).powi(2)).sum();
            d.sqrt() / o.iter().map(|a| a * a).sum::<f64>().sqrt()
        }
        _ => f64::NAN,
    };
    LobeComparison {
        floor_ratio: ratio(edited.floor, original.floor),
        peak_ratio: ratio(edited.peak, original.peak),
        hwhm_ratio: ratio(edited.hwhm_deg.unwrap_or(f64::NAN), original.hwhm_deg.unwrap_or(0.0)),
        colour_shift,
        dark_hole: dark_hole(original, edited),
    }
}

/// Whether `edited` has a dark centre at theta_h ~ 0 that `original` does not.
pub fn dark_hole(original: &Lobe, edited: &Lobe) -> bool {
    edited.has_dark_centre() && !original.has_dark_centre()
}

/// How far (Euclidean, in RGB chromaticity) the centre's colour of `other` is from
/// `original`'s; NaN where either is undefined.
pub fn centre_shift(original: &Lobe, other: &Lobe) -> f64 {
    match (original.centre_colour, other.centre_colour) {
        (Some(o), Some(e)) => o.iter().zip(&e).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt(),
        _ => f64::NAN,
    }
}

/// Whether the highlight's centre of `other` changed colour: [`centre_shift`] above
/// [`TINT_SHIFT`]. A centre that vanished (no positive sum) where the original's is defined
/// counts as tinted.
pub fn tinted_centre(original: &Lobe, other: &Lobe) -> bool {
    match (original.centre_colour, other.centre_colour) {
        (Some(_), None) => true,
        _ => centre_shift(original, other) > TINT_SHIFT,
    }
}

/// The bar an edit is held to (beside "no dark hole", which every edit is held to).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LobeBar {
    /// Roughness x2: the HWHM grows >= 1.4x.
    Widen,
    /// Roughness x0.5: the HWHM shrinks to <= 0.75x.
    Narrow,
    /// Diffuse albedo x0.5: the floor at 0.35-0.65x, the peak within 25%, its colour within
    /// 20%.
    HalveDiffuse,
}

impl LobeBar {
    /// Every bar, in the order of [`LobeTally::bars`].
    pub const ALL: [LobeBar; 3] = [LobeBar::Widen, LobeBar::Narrow, LobeBar::HalveDiffuse];

    /// The position of this bar in [`LobeBar::ALL`].
    pub fn index(self) -> usize {
        match self {
            Self::Widen => 0,
            Self::Narrow => 1,
            Self::HalveDiffuse => 2,
        }
    }

    /// The bar of `edit`: roughness scaled by 2 or 0.5, or the diffuse albedo scaled by 0.5,
    /// with nothing else changed; `None` for any other edit.
    pub fn for_edit(edit: &Edit) -> Option<Self> {
        let is = |s: f64, v: f64| (s - v).abs() < 1e-9;
        match (edit.diffuse, edit.specular, edit.roughness) {
            (None, None, Some(ScalarEdit::Scale(s))) if is(s, 2.0) => Some(Self::Widen),
            (None, None, Some(ScalarEdit::Scale(s))) if is(s, 0.5) => Some(Self::Narrow),
            (Some(ColourEdit::Scale(s)), None, None) if is(s, 0.5) => Some(Self::HalveDiffuse),
            _ => None,
        }
    }

    /// A one-word name for CSV columns.
    pub fn key(self) -> &'static str {
        match self {
            Self::Widen => "widen",
            Self::Narrow => "narrow",
            Self::HalveDiffuse => "halve-diffuse",
        }
    }

    /// What the bar asks, for tables.
    pub fn name(self) -> &'static str {
        match self {
            Self::Widen => "roughness x2 widens >= 1.4x",
            Self::Narrow => "roughness x0.5 narrows <= 0.75x",
            Self::HalveDiffuse => "diffuse x0.5: floor 0.35-0.65x, peak and colour kept",
        }
    }

    /// Whether `c` meets this bar (its own condition only; see [`verdict`] for the dark hole).
    pub fn meets(self, c: &LobeComparison) -> bool {
        match self {
            Self::Widen => c.hwhm_ratio >= WIDEN_MIN_RATIO,
            Self::Narrow => c.hwhm_ratio <= NARROW_MAX_RATIO,
            Self::HalveDiffuse => {
                (DIFFUSE_FLOOR_RATIO.0..=DIFFUSE_FLOOR_RATIO.1).contains(&c.floor_ratio)
                    && (c.peak_ratio - 1.0).abs() <= DIFFUSE_PEAK_TOLERANCE
                    && c.colour_shift <= DIFFUSE_COLOUR_TOLERANCE
            }
        }
    }
}

/// The verdict on one edit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LobeVerdict {
    /// The bar of the edit, if one applies.
    pub bar: Option<LobeBar>,
    /// Whether it meets that bar (`None` when no bar applies).
    pub meets_bar: Option<bool>,
    /// Whether it left a dark hole.
    pub dark_hole: bool,
}

impl LobeVerdict {
    /// Meets its bar (if any) and leaves no dark hole.
    pub fn passes(&self) -> bool {
        self.meets_bar != Some(false) && !self.dark_hole
    }
}

/// The verdict on `c`, the comparison of an edit held to `bar`.
pub fn verdict(bar: Option<LobeBar>, c: &LobeComparison) -> LobeVerdict {
    LobeVerdict { bar, meets_bar: bar.map(|b| b.meets(c)), dark_hole: c.dark_hole }
}

/// The lobe measures of one edit: how its lobe compares with the original's and the verdict of
/// the bar it is held to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditLobe {
    pub comparison: LobeComparison,
    pub verdict: LobeVerdict,
}

/// Measures the lobe of `edited`, the result of `edit` on a material whose lobe is `original`,
/// and judges it by the edit's bar ([`LobeBar::for_edit`]). Fails as [`Lobe::of`] does.
pub fn judge_edit(original: &Lobe, edited: &MerlTable, edit: &Edit) -> Result<EditLobe> {
    let comparison = compare(original, &Lobe::of(edited)?);
    Ok(EditLobe { comparison, verdict: verdict(LobeBar::for_edit(edit), &comparison) })
}

/// How many of a set of edits each bar held, and how many of those met it and passed (met it
/// without a dark hole).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BarCount {
    pub held: usize,
    pub met: usize,
    pub passed: usize,
}

/// Counts over a set of edits' verdicts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LobeTally {
    /// Edits counted.
    pub edits: usize,
    /// Edits that left a dark hole.
    pub dark_holes: usize,
    /// Per bar, in the order [`LobeBar::ALL`].
    pub bars: [BarCount; 3],
}

impl LobeTally {
    /// Counts `verdicts`.
    pub fn of<'a>(verdicts: impl IntoIterator<Item = &'a LobeVerdict>) -> Self {
        let mut t = Self::default();
        for v in verdicts {
            t.edits += 1;
            t.dark_holes += usize::from(v.dark_hole);
            if let Some(bar) = v.bar {
                let count = &mut t.bars[bar.index()];
                count.held += 1;
                count.met += usize::from(v.meets_bar == Some(true));
                count.passed += usize::from(v.passes());
            }
        }
        t
    }

    /// The count of `bar`.
    pub fn bar(&self, bar: LobeBar) -> BarCount {
        self.bars[bar.index()]
    }
}

#[cfg(test)]
mod tests;
