//! The lobe measures on tabulated analytic materials and hand-made pairs of tables.

use super::*;
use deepbrdf_data::ggx::{ggx, Ggx};
use deepbrdf_data::merl::coords::HalfDiff;
use deepbrdf_data::merl::{INVALID_VALUE, VALUES};
use deepbrdf_data::testing::tabulate;
use std::f64::consts::PI;

/// Lambertian `diffuse` + GGX (`alpha`, Schlick `f0`) times `lobe_scale`, tabulated at the
/// cells' sample angles; the GGX part is zero below `hole_deg` of theta_h.
fn table(alpha: f64, f0: f64, diffuse: [f64; 3], lobe_scale: f64, hole_deg: f64) -> MerlTable {
    let spec = Ggx { alpha, f0: [f0; 3], diffuse: [0.0; 3] };
    tabulate(|wi, wo| {
        let s = match HalfDiff::from_dirs(wi, wo).theta_h.to_degrees() < hole_deg {
            true => [0.0; 3],
            false => ggx(&spec, wi, wo),
        };
        std::array::from_fn(|c| diffuse[c] / PI + lobe_scale * s[c])
    })
}

fn lobe_of(table: &MerlTable) -> Lobe {
    match Lobe::of(table) {
        Ok(l) => l,
        Err(e) => panic!("{e}"),
    }
}

/// The lobe of [`table`].
fn material(alpha: f64, f0: f64, diffuse: [f64; 3], lobe_scale: f64, hole_deg: f64) -> Lobe {
    lobe_of(&table(alpha, f0, diffuse, lobe_scale, hole_deg))
}

const ALBEDO: [f64; 3] = [0.6, 0.4, 0.2];

#[test]
fn lobe_hwhm_grows_with_alpha_and_the_floor_is_the_albedo() {
    let alphas = [0.02, 0.05, 0.1, 0.2, 0.4];
    let lobes: Vec<Lobe> = alphas.iter().map(|&a| material(a, 0.04, ALBEDO, 1.0, 0.0)).collect();
    let widths: Vec<f64> = lobes.iter().map(|l| l.hwhm_deg.unwrap_or(f64::NAN)).collect();
    assert!(widths.windows(2).all(|w| w[1] > w[0]), "{widths:?}");
    // GGX's D falls to half its peak at tan^2 theta_h = (sqrt 2 - 1) alpha^2 for small
    // alpha (solve ((alpha^2 - 1) c^2 + 1)^2 = 2 alpha^4): theta_h ~ 0.644 alpha rad, so the
    // width doubles with alpha.
    for (a, w) in alphas.iter().zip(&widths).take(3) {
        let expected = (((2f64).sqrt() - 1.0).sqrt() * a).atan().to_degrees();
        assert!((w / expected - 1.0).abs() < 0.2, "alpha {a}: {w} vs {expected}");
    }
    for i in 0..2 {
        let r = widths[i + 2] / widths[i + 1];
        assert!((1.7..2.3).contains(&r), "alpha x2 from {}: width x{r}", alphas[i + 1]);
    }
    // The floor is the Lambertian albedo / pi (the lobe's tail above 45 deg adds little).
    let want = luminance(ALBEDO.map(|a| a / PI));
    for (a, l) in alphas.iter().zip(&lobes).take(4) {
        assert!((l.floor / want - 1.0).abs() < 0.03, "alpha {a}: {} vs {want}", l.floor);
        assert!(l.peak_theta_h_deg < 0.1 && !l.has_dark_centre(), "{a}");
        // The lobe (f0 grey) is white.
        let colour = l.peak_colour.unwrap_or([0.0; 3]);
        assert!(colour.iter().all(|c| (c - 1.0 / 3.0).abs() < 0.01), "{colour:?}");
    }
}

#[test]
fn a_zeroed_centre_is_a_dark_hole_and_the_bars_judge_the_edits() {
    let original = material(0.1, 0.04, ALBEDO, 1.0, 0.0);
    let holed = material(0.1, 0.04, ALBEDO, 1.0, 3.0);
    assert!(holed.has_dark_centre() && holed.peak_theta_h_deg >= 3.0, "{holed:?}");
    assert!(dark_hole(&original, &holed));
    assert!(!dark_hole(&original, &original) && !dark_hole(&holed, &holed));
    assert!(compare(&original, &holed).dark_hole);

    let same = compare(&original, &original);
    assert_eq!((same.floor_ratio, same.peak_ratio, same.hwhm_ratio), (1.0, 1.0, 1.0));
    assert!(verdict(None, &same).passes() && !verdict(None, &compare(&original, &holed)).passes());

    let halve = Edit { diffuse: Some(ColourEdit::Scale(0.5)), ..Edit::default() };
    let bar = LobeBar::for_edit(&halve);
    assert_eq!(bar, Some(LobeBar::HalveDiffuse));
    let halved = compare(&original, &material(0.1, 0.04, ALBEDO.map(|a| a / 2.0), 1.0, 0.0));
    assert!((halved.floor_ratio - 0.5).abs() < 0.02, "{halved:?}");
    assert!((halved.peak_ratio - 1.0).abs() < 0.02, "{halved:?}");
    let v = verdict(bar, &halved);
    assert!(v.meets_bar == Some(true) && v.passes(), "{v:?}");
    let doubled = compare(&original, &material(0.1, 0.04, ALBEDO.map(|a| a / 2.0), 2.0, 0.0));
    let v = verdict(bar, &doubled);
    assert!(v.meets_bar == Some(false) && !v.passes(), "{doubled:?}");
    // A lobe turned red at the same luminance (Rec. 709 red weight 0.2126) over a halved
    // floor fails on its colour alone.
    let tinted = MerlTable::from_fn(|h, _, _| {
        let d = deepbrdf_data::ggx::distribution(0.1, theta_h_of(h).cos());
        [(0.1 / PI + 0.1 / 0.2126 * d) as f32, (0.1 / PI) as f32, (0.1 / PI) as f32]
    });
    let grey = MerlTable::from_fn(|h, _, _| {
        let d = deepbrdf_data::ggx::distribution(0.1, theta_h_of(h).cos()) as f32;
        [0.2 / PI as f32 + 0.1 * d; 3]
    });
    let c = compare(&lobe_of(&grey), &lobe_of(&tinted));
    assert!((c.floor_ratio - 0.5).abs() < 0.01 && (c.peak_ratio - 1.0).abs() < 0.01, "{c:?}");
    assert!(c.colour_shift > DIFFUSE_COLOUR_TOLERANCE && !LobeBar::HalveDiffuse.meets(&c));

    let wide = compare(&original, &material(0.2, 0.04, ALBEDO, 1.0, 0.0));
    let narrow = compare(&original, &material(0.05, 0.04, ALBEDO, 1.0, 0.0));
    assert!(LobeBar::Widen.meets(&wide) && !LobeBar::Narrow.meets(&wide), "{wide:?}");
    assert!(LobeBar::Narrow.meets(&narrow) && !LobeBar::Widen.meets(&narrow), "{narrow:?}");
    let rough = |s| Edit { roughness: Some(ScalarEdit::Scale(s)), ..Edit::default() };
    assert_eq!(LobeBar::for_edit(&rough(2.0)), Some(LobeBar::Widen));
    assert_eq!(LobeBar::for_edit(&rough(0.5)), Some(LobeBar::Narrow));
    assert_eq!(LobeBar::for_edit(&rough(1.5)), None);
    assert_eq!(LobeBar::for_edit(&Edit::default()), None);
}

#[test]
fn tables_without_the_needed_cells_are_errors() {
    let empty = MerlTable::from_values(vec![INVALID_VALUE; VALUES]);
    let empty = match empty {
        Ok(t) => t,
        Err(e) => panic!("{e}"),
    };
    assert!(matches!(Lobe::of(&empty), Err(EvalError::Invalid(_))));
    assert!(specular_profile(&empty).is_err());
    // Valid only below 45 deg of theta_h: no floor.
    let mut low = MerlTable::from_fn(|_, _, _| [0.1; 3]);
    let cut = cell_index(N_THETA_H * 2 / 3, 0, 0);
    for c in 0..3 {
        low.values_mut()[c * CELLS + cut..(c + 1) * CELLS].fill(INVALID_VALUE);
    }
    assert!(Lobe::of(&low).is_err());
    // A lobe-less table is measured: no peak above the floor, no width, no hole.
    let flat = lobe_of(&MerlTable::from_fn(|_, _, _| [0.1; 3]));
    assert!(flat.peak.abs() < 1e-6 && flat.hwhm_deg.is_none() && !flat.has_dark_centre());
}

#[test]
fn judge_edit_and_tally_a_hand_made_pair() {
    let original = table(0.1, 0.04, ALBEDO, 1.0, 0.0);
    let lobe = lobe_of(&original);
    let rough = |s| Edit { roughness: Some(ScalarEdit::Scale(s)), ..Edit::default() };
    let judge = |edited: &MerlTable, edit: &Edit| match judge_edit(&lobe, edited, edit) {
        Ok(j) => j,
        Err(e) => panic!("{e}"),
    };
    let wide = judge(&table(0.2, 0.04, ALBEDO, 1.0, 0.0), &rough(2.0));
    // Wider still, but dark at the centre: meets the bar and fails.
    let holed = judge(&table(0.4, 0.04, ALBEDO, 1.0, 3.0), &rough(2.0));
    let narrow = judge(&table(0.05, 0.04, ALBEDO, 1.0, 0.0), &rough(0.5));
    let identity = judge(&original, &Edit::default());
    assert!(wide.verdict.passes() && narrow.verdict.passes(), "{wide:?} {narrow:?}");
    assert_eq!(holed.verdict.meets_bar, Some(true), "{holed:?}");
    assert!(holed.verdict.dark_hole && !holed.verdict.passes());
    assert_eq!(identity.verdict, LobeVerdict { bar: None, meets_bar: None, dark_hole: false });
    let all = [wide, holed, narrow, identity];
    let tally = LobeTally::of(all.iter().map(|j| &j.verdict));
    assert_eq!((tally.edits, tally.dark_holes), (4, 1));
    assert_eq!(tally.bar(LobeBar::Widen), BarCount { held: 2, met: 2, passed: 1 });
    assert_eq!(tally.bar(LobeBar::Narrow), BarCount { held: 1, met: 1, passed: 1 });
    assert_eq!(tally.bar(LobeBar::HalveDiffuse), BarCount::default());
    let empty = MerlTable::from_values(vec![INVALID_VALUE; VALUES]);
    assert!(empty.map(|t| judge_edit(&lobe, &t, &rough(2.0)).is_err()).unwrap_or(false));
}

#[test]
fn a_recoloured_centre_is_tinted_and_a_grey_one_is_not() {
    // A grey (f0 grey) highlight on an orange floor; the same highlight tinted green.
    let original = material(0.05, 0.04, ALBEDO, 1.0, 0.0);
    let colour = original.centre_colour.unwrap_or([0.0; 3]);
    // The centre is mostly the white highlight: close to grey, pulled a little toward orange.
    assert!(colour[0] > colour[1] && colour[1] > colour[2] && colour[0] < 0.5, "{colour:?}");
    assert_eq!(centre_shift(&original, &original), 0.0);
    assert!(!tinted_centre(&original, &original));
    // Brighter or darker by the same factor in every channel: not tinted.
    let brighter = material(0.05, 0.04, ALBEDO, 1.5, 0.0);
    assert!(centre_shift(&original, &brighter) < 0.02 && !tinted_centre(&original, &brighter));
    // The lobe's green halved and its blue removed (a table of the same floor): tinted.
    let spec = Ggx { alpha: 0.05, f0: [0.04, 0.02, 0.0], diffuse: [0.0; 3] };
    let tinted = lobe_of(&tabulate(|wi, wo| {
        let s = ggx(&spec, wi, wo);
        std::array::from_fn(|c| ALBEDO[c] / PI + s[c])
    }));
    let shift = centre_shift(&original, &tinted);
    assert!(shift > TINT_SHIFT && tinted_centre(&original, &tinted), "shift {shift}");
    // A centre that went black where the original's was lit is tinted too.
    let mut black = table(0.05, 0.04, ALBEDO, 1.0, 0.0);
    for h in 0..CENTRE_BINS {
        for d in 0..N_THETA_D {
            for p in 0..N_PHI_D {
                let cell = cell_index(h, d, p);
                for c in 0..3 {
                    let v = &mut black.values_mut()[c * CELLS + cell];
                    *v = v.min(0.0);
                }
            }
        }
    }
    let black = lobe_of(&black);
    assert!(black.centre_colour.is_none() && tinted_centre(&original, &black));
}
