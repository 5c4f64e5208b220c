//! A table's parts: the decomposition an edit works on. §5.1 of Hu et al. 2020 edits one
//! Lambertian + GGX model; a measured or layered material has more: a Lambertian floor, up to
//! two microfacet lobes (a sharp spike and a broad haze: a coat over a rough base, a two-lobe
//! plastic), a retro-reflective ridge along theta_d ~ 0, and a grazing sheen. Each part has its
//! own shape parameter and colour, fitted to the table itself ([`fit`]). What no part explains,
//! the residual, is shared among the parts, mostly to the part that dominates each cell
//! ([`Parts::split`]), so the table's parts sum to the table exactly and none is negative: an
//! edit of one part ([`edit`]) carries that part's share of the measurement's own shape and
//! leaves the others' shares where they were.
//!
//! The parts' shapes (all per unit colour, 1/sr):
//! - floor: Oren and Nayar's rough diffuse term at facet deviation sigma, Lambert's `1 / pi` at
//!   sigma 0 (the corpus' `Diffuse`), optionally under a clear coat of index eta, which lets
//!   through `(1 - F(cos_i)) (1 - F(cos_o)) / (1 - F(1))^2` of it (dielectric Fresnel; a
//!   lacquered paint or a plastic darkens towards grazing angles). The colour is the albedo seen
//!   at normal incidence;
//! - lobe: `D G1(i) G1(o) / (4 cos_i cos_o)` with GGX's or Beckmann's D and Smith's G1
//!   (Walter et al. 2007; the corpus' `Distribution`) times `(1 - m)` for its normal-incidence
//!   colour and `m` for its grazing colour, with `m = (1 - cos theta_d)^5` (Schlick's Fresnel,
//!   the colours free and non-negative);
//! - retro-reflective ridge: `(n + 1) / (2 pi) max(wi . wo, 0)^n` (a Lafortune lobe about the
//!   incident direction; `wi . wo = cos 2 theta_d` on the half-vector grid);
//! - sheen: `D_charlie(r) / (4 (cos_i + cos_o - cos_i cos_o))` (Estevez and Kulla 2017 with
//!   Neubelt and Pettineo's visibility, the corpus' sheen).

mod design;
pub mod edit;
pub mod fit;

pub use edit::{fit_and_edit, parts_edit};
pub use fit::{fit_parts, PartsConfig, PartsFit};

use deepbrdf_data::corpus::diffuse::Diffuse;
use deepbrdf_data::corpus::fresnel::dielectric;
pub use deepbrdf_data::corpus::microfacet::Distribution;
use deepbrdf_data::corpus::sheen::charlie;
use deepbrdf_data::merl::coords::HalfDiff;
use deepbrdf_data::merl::grid::{phi_d_of, theta_d_of, theta_h_of};
use deepbrdf_data::MerlTable;
use std::f64::consts::PI;

/// A lobe at least this rough whose colour is at least [`BODY_MIN_SATURATION`] saturated, over
/// a floor, is light scattered in the material's body rather than reflected at its surface
/// ([`PartLobe::is_body`]).
pub const BODY_MIN_ALPHA: f64 = 0.7;
pub const BODY_MIN_SATURATION: f64 = 0.5;

/// Most lobes of a decomposition.
pub const MAX_LOBES: usize = 2;
/// The parts' places in [`PartValues`].
pub const FLOOR: usize = 0;
/// The first lobe's place; lobe `k` is at `LOBE + k`.
pub const LOBE: usize = 1;
pub const RETRO: usize = LOBE + MAX_LOBES;
pub const SHEEN: usize = RETRO + 1;
/// Number of places in [`PartValues`].
pub const PLACES: usize = SHEEN + 1;

/// Each part's value (1/sr) per channel at one cell, by place ([`FLOOR`], [`LOBE`] + k,
/// [`RETRO`], [`SHEEN`]); an absent part is 0.
pub type PartValues = [[f64; 3]; PLACES];

/// One microfacet lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartLobe {
    pub distribution: Distribution,
    pub alpha: f64,
    /// Colour at normal incidence (Schlick's `F0` times the lobe's weight).
    pub normal: [f64; 3],
    /// Colour reached at grazing theta_d (the weight of `(1 - cos theta_d)^5`).
    pub grazing: [f64; 3],
}

/// The retro-reflective ridge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartRetro {
    pub colour: [f64; 3],
    pub exponent: f64,
}

/// The sheen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartSheen {
    pub colour: [f64; 3],
    pub roughness: f64,
}

/// The diffuse floor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartFloor {
    pub albedo: [f64; 3],
    /// Oren-Nayar's facet deviation (radians); 0 is Lambertian.
    pub sigma: f64,
    /// The index of a clear coat over the floor, if any.
    pub coat: Option<f64>,
}

/// A table's parts (module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Parts {
    pub floor: PartFloor,
    /// At most [`MAX_LOBES`], sharpest first.
    pub lobes: Vec<PartLobe>,
    pub retro: Option<PartRetro>,
    pub sheen: Option<PartSheen>,
}

/// The directions and angles of a cell that the parts depend on.
#[derive(Clone, Copy, Debug)]
pub struct CellAngles {
    pub wi: [f64; 3],
    pub wo: [f64; 3],
    pub cos_h: f64,
    pub cos_i: f64,
    pub cos_o: f64,
    pub cos_d: f64,
    /// `wi . wo = cos 2 theta_d`.
    pub cos_2d: f64,
}

impl CellAngles {
    /// The angles at half-vector angle `theta_h` (phi_h = 0) and difference angles (`theta_d`,
    /// `phi_d`) (Rusinkiewicz 1998); None where either direction is on or below the horizon.
    pub fn at(theta_h: f64, theta_d: f64, phi_d: f64) -> Option<Self> {
        let (wi, wo) = HalfDiff { theta_h, phi_h: 0.0, theta_d, phi_d }.to_dirs();
        (wi[2] > 0.0 && wo[2] > 0.0).then(|| Self {
            wi,
            wo,
            cos_h: theta_h.cos(),
            cos_i: wi[2],
            cos_o: wo[2],
            cos_d: theta_d.cos(),
            cos_2d: (2.0 * theta_d).cos(),
        })
    }

    /// The angles of MERL cell (theta_h bin `i`, theta_d bin `j`, phi_d bin `k`).
    pub fn of(i: usize, j: usize, k: usize) -> Option<Self> {
        Self::at(theta_h_of(i), theta_d_of(j), phi_d_of(k))
    }

    /// Schlick's grazing weight `(1 - cos theta_d)^5`.
    pub fn grazing(&self) -> f64 {
        (1.0 - self.cos_d.clamp(0.0, 1.0)).powi(5)
    }
}

/// The floor's shape at facet deviation `sigma` under a coat of index `coat`, if any.
pub fn floor_shape(sigma: f64, coat: Option<f64>, a: &CellAngles) -> f64 {
    let base = Diffuse::OrenNayar { albedo: [1.0; 3], sigma }.eval(a.wi, a.wo)[0];
    match coat {
        None => base,
        Some(eta) => {
            let t = |cos: f64| 1.0 - dielectric(eta, cos);
            base * t(a.cos_i) * t(a.cos_o) / (t(1.0) * t(1.0))
        }
    }
}

/// A lobe's shape at roughness `alpha` (module documentation), without its colour.
pub fn lobe_shape(distribution: Distribution, alpha: f64, a: &CellAngles) -> f64 {
    let g = distribution.g1(alpha, a.cos_i) * distribution.g1(alpha, a.cos_o);
    distribution.d(alpha, a.cos_h) * g / (4.0 * a.cos_i * a.cos_o)
}

/// The retro-reflective ridge's shape at exponent `n`.
pub fn retro_shape(n: f64, a: &CellAngles) -> f64 {
    (n + 1.0) / (2.0 * PI) * a.cos_2d.max(0.0).powf(n)
}

/// The sheen's shape at roughness `r`.
pub fn sheen_shape(r: f64, a: &CellAngles) -> f64 {
    charlie(r, a.cos_h) / (4.0 * (a.cos_i + a.cos_o - a.cos_i * a.cos_o))
}

impl PartLobe {
    /// Whether the lobe is the body's: nearly as wide as the roughness range and tinted over a
    /// floor. A dielectric's surface reflection has the light's colour at every angle (Fresnel's
    /// reflectance depends on the index alone, which barely varies over the visible range), so
    /// a wide saturated lobe over a diffuse floor (a plastic's red brightening towards grazing
    /// angles) belongs with the floor, and the edits treat it as floor; a metal has no floor.
    pub fn is_body(&self, floor: &PartFloor) -> bool {
        let saturation = |x: [f64; 3]| {
            let (lo, hi) = (
                x.iter().copied().fold(f64::INFINITY, f64::min),
                x.iter().copied().fold(0.0, f64::max),
            );
            if hi > 0.0 {
                1.0 - lo / hi
            } else {
                0.0
            }
        };
        let has_floor = floor.albedo.iter().any(|&a| a > 0.0);
        self.alpha >= BODY_MIN_ALPHA && has_floor && saturation(self.normal) >= BODY_MIN_SATURATION
    }

    /// The lobe's value per channel at `a`, at roughness `alpha` (its own or an edited one).
    pub fn value_at(&self, alpha: f64, a: &CellAngles) -> [f64; 3] {
        let (shape, m) = (lobe_shape(self.distribution, alpha, a), a.grazing());
        std::array::from_fn(|c| shape * (self.normal[c] * (1.0 - m) + self.grazing[c] * m))
    }
}

impl Parts {
    /// Each part's value at `a`.
    pub fn values(&self, a: &CellAngles) -> PartValues {
        let mut v = [[0.0; 3]; PLACES];
        let floor = floor_shape(self.floor.sigma, self.floor.coat, a);
        v[FLOOR] = self.floor.albedo.map(|x| x * floor);
        for (k, lobe) in self.lobes.iter().enumerate() {
            v[LOBE + k] = lobe.value_at(lobe.alpha, a);
        }
        if let Some(r) = &self.retro {
            let s = retro_shape(r.exponent, a);
            v[RETRO] = r.colour.map(|x| x * s);
        }
        if let Some(s) = &self.sheen {
            let shape = sheen_shape(s.roughness, a);
            v[SHEEN] = s.colour.map(|x| x * shape);
        }
        v
    }

    /// The table's value `t` at `a` split among the parts: where `t` is at least the parts'
    /// sum, each part keeps its value and the excess goes to the parts in proportion to the
    /// squares of their values (mostly to the part that dominates the cell: a lobe's peak
    /// higher than its fit stays lobe, a floor higher than its fit stays floor); below it,
    /// every part is scaled by the same factor (none is negative). All 0 where the parts sum to
    /// 0, for the caller to keep.
    pub fn split(&self, t: [f64; 3], a: &CellAngles) -> PartValues {
        let v = self.values(a);
        let mut out = [[0.0; 3]; PLACES];
        for c in 0..3 {
            let total: f64 = v.iter().map(|p| p[c]).sum();
            if !(total > 0.0) {
                continue;
            }
            let excess = t[c] - total;
            let squares: f64 = v.iter().map(|p| p[c] * p[c]).sum();
            for p in 0..PLACES {
                out[p][c] = match excess >= 0.0 {
                    true => v[p][c] + excess * v[p][c] * v[p][c] / squares,
                    false => v[p][c] * t[c] / total,
                };
            }
        }
        out
    }

    /// The parts tabulated on the MERL grid (cells below the horizon hold 0).
    pub fn table(&self) -> MerlTable {
        MerlTable::from_fn(|i, j, k| match CellAngles::of(i, j, k) {
            Some(a) => {
                let v = self.values(&a);
                std::array::from_fn(|c| v.iter().map(|p| p[c]).sum::<f64>() as f32)
            }
            None => [0.0; 3],
        })
    }

    /// The parts in words, one per line: each part's shape and RGB colour.
    pub fn describe(&self) -> String {
        let rgb = |x: [f64; 3]| format!("{:.4} {:.4} {:.4}", x[0], x[1], x[2]);
        let f = &self.floor;
        let mut lines = vec![format!("floor: albedo {}, sigma {:.2}", rgb(f.albedo), f.sigma)];
        if let Some(eta) = f.coat {
            lines[0] += &format!(", under a coat of index {eta:.2}");
        }
        for l in &self.lobes {
            let name = match l.distribution {
                Distribution::Ggx => "GGX",
                Distribution::Beckmann => "Beckmann",
            };
            let body = if l.is_body(f) { " (the body's: edited with the floor)" } else { "" };
            lines.push(format!(
                "{name} lobe: alpha {:.4}, normal {}, grazing {}{body}",
                l.alpha,
                rgb(l.normal),
                rgb(l.grazing)
            ));
        }
        if let Some(r) = &self.retro {
            lines.push(format!("retro-reflective ridge: n {:.1}, {}", r.exponent, rgb(r.colour)));
        }
        if let Some(s) = &self.sheen {
            lines.push(format!("sheen: roughness {:.2}, {}", s.roughness, rgb(s.colour)));
        }
        lines.join("\n")
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Parts with every kind: a rough floor, a spike and a haze, a ridge and a sheen.
    pub(crate) fn every_part() -> Parts {
        Parts {
            floor: PartFloor { albedo: [0.3, 0.2, 0.1], sigma: 0.3, coat: Some(1.5) },
            lobes: vec![
                PartLobe {
                    distribution: Distribution::Beckmann,
                    alpha: 0.01,
                    normal: [0.04; 3],
                    grazing: [1.0; 3],
                },
                PartLobe {
                    distribution: Distribution::Beckmann,
                    alpha: 0.2,
                    normal: [0.1, 0.05, 0.02],
                    grazing: [0.3; 3],
                },
            ],
            retro: Some(PartRetro { colour: [0.1, 0.2, 0.3], exponent: 20.0 }),
            sheen: Some(PartSheen { colour: [0.3; 3], roughness: 0.5 }),
        }
    }

    #[test]
    fn a_table_of_parts_is_fitted_back() {
        let truth = every_part();
        let fit = fit_parts(&truth.table(), &PartsConfig::default()).unwrap();
        let got = &fit.parts;
        assert!(fit.relative_error < 1e-4, "{}: {}", fit.relative_error, got.describe());
        let near = |a: f64, b: f64, tol: f64| (a / b - 1.0).abs() < tol;
        assert_eq!(got.lobes.len(), 2, "{}", got.describe());
        for (g, t) in got.lobes.iter().zip(&truth.lobes) {
            assert_eq!(g.distribution, t.distribution, "{}", got.describe());
            assert!(near(g.alpha, t.alpha, 0.05), "{}", got.describe());
            assert!(near(g.normal[0], t.normal[0], 0.1), "{}", got.describe());
        }
        let (r, s) = (got.retro.unwrap(), got.sheen.unwrap());
        assert!(near(r.exponent, 20.0, 0.1) && near(r.colour[2], 0.3, 0.1), "{}", got.describe());
        assert!(near(s.roughness, 0.5, 0.1) && near(s.colour[0], 0.3, 0.1), "{}", got.describe());
        assert!((got.floor.sigma - 0.3).abs() < 0.05, "{}", got.describe());
        assert_eq!(got.floor.coat, Some(1.5), "{}", got.describe());
        for c in 0..3 {
            assert!(near(got.floor.albedo[c], truth.floor.albedo[c], 0.03), "{}", got.describe());
        }
    }

    #[test]
    fn splits_sum_to_the_table_and_a_bad_config_is_refused() {
        let parts = every_part();
        for (i, j, k) in [(0, 0, 0), (3, 40, 90), (60, 80, 10), (89, 5, 170)] {
            let Some(a) = CellAngles::of(i, j, k) else { continue };
            let model = parts.values(&a);
            for scale in [0.5, 1.0, 1.7] {
                let t: [f64; 3] =
                    std::array::from_fn(|c| scale * model.iter().map(|p| p[c]).sum::<f64>());
                let split = parts.split(t, &a);
                for c in 0..3 {
                    let sum: f64 = split.iter().map(|p| p[c]).sum();
                    assert!((sum / t[c] - 1.0).abs() < 1e-12, "{i} {j} {k} x{scale}: {sum}");
                    assert!(split.iter().all(|p| p[c] >= 0.0));
                }
            }
        }
        // Only a wide, saturated lobe over a floor is the body's.
        let red = PartLobe {
            distribution: Distribution::Ggx,
            alpha: 0.9,
            normal: [0.3, 0.05, 0.0],
            grazing: [0.4, 0.0, 0.0],
        };
        let grey = PartLobe { normal: [0.1; 3], ..red };
        let narrow = PartLobe { alpha: 0.3, ..red };
        let bare = PartFloor { albedo: [0.0; 3], ..parts.floor };
        assert!(red.is_body(&parts.floor));
        assert!(!grey.is_body(&parts.floor) && !narrow.is_body(&parts.floor));
        assert!(!red.is_body(&bare), "a metal has no floor");
        let table = parts.table();
        for bad in [
            PartsConfig { lobe_grid: 1, ..Default::default() },
            PartsConfig { floor_sigmas: vec![2.0], ..Default::default() },
            PartsConfig { retro_exponents: vec![0.0], ..Default::default() },
        ] {
            let e = fit_parts(&table, &bad).unwrap_err().to_string();
            assert!(e.contains("parts fit"), "{e}");
        }
        let empty = MerlTable::from_fn(|_, _, _| [0.0; 3]);
        assert!(fit_parts(&empty, &PartsConfig::default())
            .unwrap_err()
            .to_string()
            .contains("valid"));
    }
}
