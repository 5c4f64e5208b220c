//! The analytic daylight model of Preetham, Shirley and Smits, "A Practical Analytic Model for
//! Daylight" (SIGGRAPH 1999): the sky's luminance and chromaticity (the Perez distribution,
//! App. A.2) and the sun's transmittance through the atmosphere (App. A.1), evaluated per
//! direction; [`super::SunSky`] tabulates them for rendering.

use crate::brdf::Rgb;
use crate::geometry::Vec3;
use std::f64::consts::PI;

/// CIE xyY to linear sRGB (D65), the standard XYZ -> sRGB matrix.
fn xyy_to_rgb(x: f64, y: f64, lum: f64) -> Rgb {
    if y <= 0.0 {
        return [0.0; 3];
    }
    let cx = x * lum / y;
    let cz = (1.0 - x - y) * lum / y;
    [
        3.2406 * cx - 1.5372 * lum - 0.4986 * cz,
        -0.9689 * cx + 1.8758 * lum + 0.0415 * cz,
        0.0557 * cx - 0.2040 * lum + 1.0570 * cz,
    ]
    .map(|v| v.max(0.0))
}

/// Coefficients A..E of the Perez sky distribution for one quantity (Preetham 1999, App. A.2).
type Perez = [f64; 5];

/// The Perez function `F(theta, gamma) = (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2 gamma)`.
#[inline]
fn perez(c: &Perez, cos_theta: f64, gamma: f64, cos_gamma: f64) -> f64 {
    (1.0 + c[0] * (c[1] / cos_theta.max(1e-3)).exp())
        * (1.0 + c[2] * (c[3] * gamma).exp() + c[4] * cos_gamma * cos_gamma)
}

/// Preetham et al.'s analytic sky luminance and chromaticity.
#[derive(Clone, Debug)]
pub struct PreethamSky {
    sun: Vec3,
    coef: [Perez; 3],
    /// Zenith values (Y in kcd/m^2, x, y) divided by `F(0, theta_s)`.
    zenith_over_f0: [f64; 3],
}

impl PreethamSky {
    /// The sky for a sun at unit direction `sun` (z up, above the horizon) and `turbidity`.
    pub fn new(sun: Vec3, turbidity: f64) -> Self {
        let t = turbidity;
        // Preetham 1999, Appendix A.2: distribution coefficients for Y, x and y.
        let coef = [
            [
                0.1787 * t - 1.4630,
                -0.3554 * t + 0.4275,
                -0.0227 * t + 5.3251,
                0.1206 * t - 2.5771,
                -0.0670 * t + 0.3703,
            ],
            [
                -0.0193 * t - 0.2592,
                -0.0665 * t + 0.0008,
                -0.0004 * t + 0.2125,
                -0.0641 * t - 0.8989,
                -0.0033 * t + 0.0452,
            ],
            [
                -0.0167 * t - 0.2608,
                -0.0950 * t + 0.0092,
                -0.0079 * t + 0.2102,
                -0.0441 * t - 1.6537,
                -0.0109 * t + 0.0529,
            ],
        ];
        let theta_s = sun.z.clamp(-1.0, 1.0).acos();
        // Zenith luminance (kcd/m^2) and chromaticities, Preetham 1999, Appendix A.2.
        let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta_s);
        let yz = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
        let th = [theta_s.powi(3), theta_s.powi(2), theta_s, 1.0];
        let poly = |m: [[f64; 4]; 3]| {
            let row = |r: [f64; 4]| r.iter().zip(th).map(|(a, b)| a * b).sum::<f64>();
            t * t * row(m[0]) + t * row(m[1]) + row(m[2])
        };
        let xz = poly([
            [0.00166, -0.00375, 0.00209, 0.0],
            [-0.02903, 0.06377, -0.03202, 0.00394],
            [0.11693, -0.21196, 0.06052, 0.25886],
        ]);
        let yz_chroma = poly([
            [0.00275, -0.00610, 0.00317, 0.0],
            [-0.04214, 0.08970, -0.04153, 0.00516],
            [0.15346, -0.26756, 0.06670, 0.26688],
        ]);
        let cos_s = theta_s.cos();
        let zenith = [yz, xz, yz_chroma];
        let zenith_over_f0 =
            std::array::from_fn(|k| zenith[k] / perez(&coef[k], 1.0, theta_s, cos_s));
        Self { sun, coef, zenith_over_f0 }
    }

    /// Sky radiance (linear sRGB, luminance in kcd/m^2) in unit direction `dir`; zero below
    /// the horizon.
    pub fn radiance(&self, dir: Vec3) -> Rgb {
        if dir.z <= 0.0 {
            return [0.0; 3];
        }
        let cos_gamma = dir.dot(self.sun).clamp(-1.0, 1.0);
        let gamma = cos_gamma.acos();
        let v: [f64; 3] = std::array::from_fn(|k| {
            self.zenith_over_f0[k] * perez(&self.coef[k], dir.z, gamma, cos_gamma)
        });
        xyy_to_rgb(v[1], v[2], v[0].max(0.0))
    }
}

/// Extraterrestrial solar illuminance, klux (about 128 klux; kcd sr / m^2).
pub const SOLAR_ILLUMINANCE_KLUX: f64 = 128.0;

/// Wavelengths (micrometres) standing for the R, G and B channels in the sun's transmittance.
const RGB_WAVELENGTHS_UM: [f64; 3] = [0.610, 0.550, 0.465];

/// Transmittance of the atmosphere for direct sunlight per RGB channel, from Preetham 1999,
/// Appendix A.1: Rayleigh scattering `exp(-0.008735 lambda^-4.08 m)` and Angstrom's aerosol
/// formula `exp(-beta lambda^-alpha m)` with `alpha = 1.3`, `beta = 0.04608 T - 0.04586`, and the
/// relative optical mass `m = 1 / (cos theta_s + 0.15 (93.885 - theta_s[deg])^-1.253)`. Ozone and
/// water-vapour absorption are left out (a few percent in the visible).
pub fn sun_transmittance(theta_s: f64, turbidity: f64) -> Rgb {
    let deg = theta_s.to_degrees();
    let m = 1.0 / (theta_s.cos() + 0.15 * (93.885 - deg).max(1e-3).powf(-1.253));
    let beta = 0.04608 * turbidity - 0.04586;
    RGB_WAVELENGTHS_UM.map(|l: f64| (-m * (0.008735 * l.powf(-4.08) + beta * l.powf(-1.3))).exp())
}
