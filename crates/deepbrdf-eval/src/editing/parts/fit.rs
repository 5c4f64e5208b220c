//! Fitting a table's [`Parts`]: non-negative least squares over the parts' colours for each
//! choice of their shape parameters, and a search over those.
//!
//! The residual of cell `x` and channel `c` is the linearised log-space residual of the
//! attribute fit (`crate::attributes::fit`), `w (f_hat - f) / (eps + w f)` with
//! `w = cos_i cos_o`, with one weight per cell from the channels' mean so that every channel
//! shares one design. For fixed shapes the model is linear in the colours (the floor's albedo,
//! each lobe's normal and grazing colours, the ridge's and the sheen's colours): each channel's
//! colours are the non-negative least-squares solution (Lawson and Hanson 1974, ch. 23) of the
//! normal equations. The shapes are searched on grids: every lobe set (none, one lobe, or two
//! lobes whose roughnesses differ by at least [`PartsConfig::lobe_ratio`]) under each floor
//! alone, then the best few lobe sets of each size under every floor with every ridge exponent
//! and sheen roughness (or none), then every lobe set and floor again with the ridge and sheen
//! found.
//! A structure is scored by its relative error (plus a small floor) times `(1 + penalty)` per
//! part, so a part is kept only where it explains a share of what is left; the chosen structure's parameters are
//! refined by golden-section search in log space, one at a time. Deterministic: no random
//! numbers, fixed reduction orders.

use super::design::{solve, Columns, Design, Samples, Shape};
use super::{Distribution, PartFloor, PartLobe, PartRetro, PartSheen, Parts, MAX_LOBES};
use crate::error::{EvalError, Result};
use crate::golden::golden_section;
use deepbrdf_data::merl::{N_PHI_D, N_THETA_D};
use deepbrdf_data::MerlTable;
use nalgebra::DVector;
use rayon::prelude::*;

/// Settings of [`fit_parts`].
#[derive(Clone, Debug, PartialEq)]
pub struct PartsConfig {
    /// Every theta_d (phi_d) index that is a multiple of this is sampled; all theta_h are.
    pub theta_d_stride: usize,
    pub phi_d_stride: usize,
    /// `eps` of the log space, in 1/sr.
    pub offset: f64,
    /// Lobe roughness grid: this many points log-spaced over `lobe_range`.
    pub lobe_grid: usize,
    pub lobe_range: (f64, f64),
    /// Two lobes differ in roughness by at least this factor.
    pub lobe_ratio: f64,
    /// Floor facet deviations (Oren-Nayar's sigma, radians), ridge exponents and sheen
    /// roughnesses tried.
    pub floor_sigmas: Vec<f64>,
    /// Floors tried with each sigma: bare (None) or under a coat of the index given.
    pub floor_coats: Vec<Option<f64>>,
    pub retro_exponents: Vec<f64>,
    pub sheen_roughness: Vec<f64>,
    /// Relative error cost of each part beyond the floor, and the relative error below which
    /// a part explains nothing worth a part (a structure's score is
    /// `(error + error_floor) (1 + penalty)^parts`).
    pub penalty: f64,
    pub error_floor: f64,
    /// Lobe sets carried from the first stage to the second, per number of lobes.
    pub keep: usize,
    /// Golden-section steps per parameter and passes over the parameters.
    pub refine_steps: usize,
    pub refine_passes: usize,
}

impl Default for PartsConfig {
    fn default() -> Self {
        Self {
            theta_d_stride: 4,
            phi_d_stride: 8,
            offset: 1e-3,
            lobe_grid: 16,
            lobe_range: (0.002, 1.0),
            lobe_ratio: 2.5,
            floor_sigmas: vec![0.0, 0.15, 0.3, 0.5, 0.75, 1.0],
            floor_coats: vec![None, Some(1.5)],
            retro_exponents: vec![2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0],
            sheen_roughness: vec![0.1, 0.2, 0.35, 0.5, 0.75, 1.0],
            penalty: 0.1,
            error_floor: 0.005,
            keep: 3,
            refine_steps: 10,
            refine_passes: 2,
        }
    }
}

/// The result of [`fit_parts`].
#[derive(Clone, Debug, PartialEq)]
pub struct PartsFit {
    pub parts: Parts,
    /// The weighted squared residual over the weighted squared table (the channels summed).
    pub relative_error: f64,
    /// Cells fitted.
    pub cells: usize,
}

/// The largest floor sigma the refinement reaches (the corpus' range).
const SIGMA_MAX: f64 = deepbrdf_data::corpus::material::SIGMA_RANGE.1;

/// Fewest valid sampled cells a fit accepts.
const MIN_CELLS: usize = 200;

/// A floor's sigma and coat index.
type Floor = (f64, Option<f64>);
/// A lobe's distribution and roughness.
type Lobe = (Distribution, f64);
/// The distributions a lobe is fitted with.
const DISTRIBUTIONS: [Distribution; 2] = [Distribution::Ggx, Distribution::Beckmann];

/// A structure: the shape parameters of each part present.
#[derive(Clone, Debug, PartialEq)]
struct Structure {
    sigma: f64,
    coat: Option<f64>,
    lobes: Vec<Lobe>,
    retro: Option<f64>,
    sheen: Option<f64>,
}

impl Structure {
    fn shapes(&self) -> Vec<Shape> {
        let mut s = vec![Shape::Floor(self.sigma, self.coat)];
        for &(d, a) in &self.lobes {
            s.extend([Shape::Lobe(d, a, false), Shape::Lobe(d, a, true)]);
        }
        s.extend(self.retro.map(Shape::Retro));
        s.extend(self.sheen.map(Shape::Sheen));
        s
    }

    fn parts(&self) -> usize {
        self.lobes.len() + usize::from(self.retro.is_some()) + usize::from(self.sheen.is_some())
    }

    /// The parameters as searched, in order: the floor's sigma, then in log space the lobes'
    /// roughnesses, the ridge's exponent and the sheen's roughness.
    fn params(&self) -> Vec<f64> {
        let alphas = self.lobes.iter().map(|l| l.1);
        let logs = alphas.chain(self.retro).chain(self.sheen).map(|v| v.ln());
        std::iter::once(self.sigma).chain(logs).collect()
    }

    fn with_param(&self, n: usize, value: f64) -> Self {
        let mut s = self.clone();
        if n == 0 {
            s.sigma = value;
            return s;
        }
        let v = value.exp();
        match (n - 1).checked_sub(s.lobes.len()) {
            None => s.lobes[n - 1].1 = v,
            Some(0) if s.retro.is_some() => s.retro = Some(v),
            Some(_) => s.sheen = Some(v),
        }
        s
    }
}

/// Fits `table`'s [`Parts`] (module documentation).
pub fn fit_parts(table: &MerlTable, config: &PartsConfig) -> Result<PartsFit> {
    validate(config)?;
    let samples = Samples::of(table, config.theta_d_stride, config.phi_d_stride, config.offset);
    let cells = samples.angles.len();
    if cells < MIN_CELLS || samples.energy.iter().sum::<f64>() <= 0.0 {
        return Err(EvalError::Invalid(format!(
            "parts fit: {cells} sampled cells are valid and non-zero (at least {MIN_CELLS} needed)"
        )));
    }
    let (lo, hi) = (config.lobe_range.0.ln(), config.lobe_range.1.ln());
    let n = config.lobe_grid;
    let alphas: Vec<f64> =
        (0..n).map(|i| (lo + (hi - lo) * i as f64 / (n - 1) as f64).exp()).collect();
    let floors: Vec<Floor> = config
        .floor_sigmas
        .iter()
        .flat_map(|&sigma| config.floor_coats.iter().map(move |&coat| (sigma, coat)))
        .collect();
    let mut shapes: Vec<Shape> = floors.iter().map(|&(s, c)| Shape::Floor(s, c)).collect();
    for d in DISTRIBUTIONS {
        for &a in &alphas {
            shapes.extend([Shape::Lobe(d, a, false), Shape::Lobe(d, a, true)]);
        }
    }
    shapes.extend(config.retro_exponents.iter().map(|&e| Shape::Retro(e)));
    shapes.extend(config.sheen_roughness.iter().map(|&r| Shape::Sheen(r)));
    let design = Design::new(&samples, shapes);
    let score = |s: &Structure| {
        let (_, err) = solve(&design.normal(&s.shapes()), &samples.energy);
        (err + config.error_floor) * (1.0 + config.penalty).powi(s.parts() as i32)
    };
    // Stage 1: the lobe sets under each floor alone.
    // No lobe, one lobe of either distribution, or two of the same.
    let mut lobe_sets: Vec<Vec<Lobe>> = vec![vec![]];
    for d in DISTRIBUTIONS {
        lobe_sets.extend(alphas.iter().map(|&a| vec![(d, a)]));
        for (i, &a) in alphas.iter().enumerate() {
            for &b in &alphas[i + 1..] {
                if b >= config.lobe_ratio * a {
                    lobe_sets.push(vec![(d, a), (d, b)]);
                }
            }
        }
    }
    let plain = |(sigma, coat): Floor, lobes: &Vec<Lobe>| Structure {
        sigma,
        coat,
        lobes: lobes.clone(),
        retro: None,
        sheen: None,
    };
    // Each lobe set's score under its best floor.
    let scored: Vec<(f64, &Vec<Lobe>)> = lobe_sets
        .par_iter()
        .map(|l| {
            let best = floors.iter().map(|&floor| score(&plain(floor, l)));
            (best.fold(f64::INFINITY, f64::min), l)
        })
        .collect();
    let mut kept: Vec<&Vec<Lobe>> = Vec::new();
    for count in 0..=MAX_LOBES {
        let mut of_count: Vec<_> = scored.iter().filter(|(_, l)| l.len() == count).collect();
        of_count.sort_by(|a, b| a.0.total_cmp(&b.0));
        kept.extend(of_count.into_iter().take(config.keep).map(|(_, l)| *l));
    }
    // Stage 2: the kept lobe sets under every floor with every ridge and sheen (or none).
    let retros: Vec<Option<f64>> =
        std::iter::once(None).chain(config.retro_exponents.iter().map(|&e| Some(e))).collect();
    let sheens: Vec<Option<f64>> =
        std::iter::once(None).chain(config.sheen_roughness.iter().map(|&r| Some(r))).collect();
    let mut candidates: Vec<Structure> = Vec::new();
    for lobes in kept {
        for &(sigma, coat) in &floors {
            for &retro in &retros {
                for &sheen in &sheens {
                    let lobes = (*lobes).clone();
                    candidates.push(Structure { sigma, coat, lobes, retro, sheen });
                }
            }
        }
    }
    let best_of = |candidates: &[Structure]| {
        candidates
            .par_iter()
            .map(|s| (score(s), s))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(score, s)| (score, s.clone()))
            .expect("a floor alone is a candidate")
    };
    let (score2, best) = best_of(&candidates);
    // Stage 3: every lobe set and floor again, with the ridge and sheen found (a strong ridge
    // can hide the lobe that fits under it from stage 1).
    let mut again: Vec<Structure> = Vec::new();
    for lobes in &lobe_sets {
        for &(sigma, coat) in &floors {
            let lobes = lobes.clone();
            again.push(Structure { sigma, coat, lobes, ..best.clone() });
        }
    }
    let (score3, best3) = best_of(&again);
    let best = if score3 < score2 { best3 } else { best };
    let (structure, colours, relative_error) = refine(&samples, best, &alphas, config);
    Ok(PartsFit { parts: parts_of(&structure, &colours), relative_error, cells })
}

/// Golden-section refinement of each parameter of `structure` within one grid step.
fn refine(
    samples: &Samples,
    mut structure: Structure,
    alphas: &[f64],
    config: &PartsConfig,
) -> (Structure, [DVector<f64>; 3], f64) {
    let step = match alphas.len() > 1 {
        true => (alphas[1] / alphas[0]).ln(),
        false => 0.0,
    };
    let mut columns = Columns::new(samples);
    let mut error_of = |s: &Structure| solve(&columns.normal(&s.shapes()), &samples.energy).1;
    for _ in 0..config.refine_passes {
        for n in 0..structure.params().len() {
            let p = structure.params()[n];
            let lobe = (1..=structure.lobes.len()).contains(&n);
            // The floor's, the ridge's and the sheen's grids are coarser: wider brackets.
            let half = match n {
                0 => 0.15,
                _ if lobe => step,
                _ => 0.7,
            };
            let (mut a, mut b) = (p - half, p + half);
            if n == 0 {
                (a, b) = (a.max(0.0), b.min(SIGMA_MAX));
            }
            if lobe {
                a = a.max(config.lobe_range.0.ln());
                b = b.min(config.lobe_range.1.ln());
                // Two lobes stay at least the lobe ratio apart, as on the grid.
                let ratio = config.lobe_ratio.ln();
                match (n, structure.lobes.len()) {
                    (1, 2) => b = b.min(structure.lobes[1].1.ln() - ratio),
                    (2, 2) => a = a.max(structure.lobes[0].1.ln() + ratio),
                    _ => {}
                }
                if a > b {
                    continue;
                }
            }
            let f = |x: f64| error_of(&structure.with_param(n, x));
            let (x, fx) = golden_section(f, a, b, config.refine_steps);
            if fx < error_of(&structure) {
                structure = structure.with_param(n, x);
            }
        }
    }
    let (colours, err) = solve(&Columns::new(samples).normal(&structure.shapes()), &samples.energy);
    (structure, colours, err)
}

/// The parts of a solved structure; lobes sharpest first, parts whose colour came out 0 left out.
fn parts_of(s: &Structure, colours: &[DVector<f64>; 3]) -> Parts {
    let at = |i: usize| -> [f64; 3] { std::array::from_fn(|c| colours[c][i]) };
    let nonzero = |v: &[f64; 3]| v.iter().any(|&x| x > 0.0);
    let mut lobes: Vec<PartLobe> = s
        .lobes
        .iter()
        .enumerate()
        .map(|(k, &(distribution, alpha))| PartLobe {
            distribution,
            alpha,
            normal: at(1 + 2 * k),
            grazing: at(2 + 2 * k),
        })
        .filter(|l| nonzero(&l.normal) || nonzero(&l.grazing))
        .collect();
    lobes.sort_by(|a, b| a.alpha.total_cmp(&b.alpha));
    let mut next = 1 + 2 * s.lobes.len();
    let retro = s.retro.map(|exponent| {
        next += 1;
        PartRetro { colour: at(next - 1), exponent }
    });
    let sheen = s.sheen.map(|roughness| PartSheen { colour: at(next), roughness });
    Parts {
        floor: PartFloor { albedo: at(0), sigma: s.sigma, coat: s.coat },
        lobes,
        retro: retro.filter(|r| nonzero(&r.colour)),
        sheen: sheen.filter(|s| nonzero(&s.colour)),
    }
}

fn validate(c: &PartsConfig) -> Result<()> {
    let bad = |what: &str| Err(EvalError::Invalid(format!("parts fit: {what}")));
    if c.theta_d_stride == 0 || c.theta_d_stride > N_THETA_D {
        return bad("theta_d stride must be in 1..=90");
    }
    if c.phi_d_stride == 0 || c.phi_d_stride > N_PHI_D {
        return bad("phi_d stride must be in 1..=180");
    }
    let (lo, hi) = c.lobe_range;
    if !(c.lobe_grid >= 2 && lo > 0.0 && hi > lo && hi.is_finite()) {
        return bad("the lobe grid needs 2 points over a positive range");
    }
    if !(c.offset > 0.0 && c.penalty >= 0.0 && c.error_floor >= 0.0 && c.lobe_ratio >= 1.0) {
        return bad("offset must be positive, penalty non-negative and the lobe ratio at least 1");
    }
    let positive = |v: &[f64]| v.iter().all(|x| x.is_finite() && *x > 0.0);
    if !(positive(&c.retro_exponents) && positive(&c.sheen_roughness)) {
        return bad("ridge exponents and sheen roughnesses must be positive");
    }
    let sigma_ok = |s: &f64| (0.0..=SIGMA_MAX).contains(s);
    if c.floor_sigmas.is_empty() || !c.floor_sigmas.iter().all(sigma_ok) {
        return bad("the floor needs at least one sigma, each in [0, 1.5]");
    }
    let coat_ok = |c: &Option<f64>| c.is_none_or(|eta| eta > 1.0 && eta.is_finite());
    if c.floor_coats.is_empty() || !c.floor_coats.iter().all(coat_ok) {
        return bad("the floor needs at least one coat (or none), each index above 1");
    }
    Ok(())
}
