//! A tabulated MERL BRDF (Matusik et al. 2003): evaluation borrows a [`MerlTable`] and looks it
//! up in Rusinkiewicz coordinates through `deepbrdf_data::merl::lookup` (the split tray_rust
//! makes between owning the table and evaluating it). A decoded DeepBRDF latent is just another
//! table, so it renders through this type too.

use super::interleaved::InterleavedTable;
use super::{Brdf, Rgb, SamplingLobe, TableSampler};
use crate::geometry::Vec3;
use deepbrdf_data::MerlTable;
use std::sync::Arc;

/// How a table is looked up between its grid points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MerlLookup {
    /// Trilinear interpolation in (theta_h index, theta_d, phi_d), on an interleaved RGB copy of
    /// the table made for speed ([`InterleavedTable`]; equal to `MerlTable::lookup_interpolated`
    /// to about 1e-6).
    #[default]
    Interpolated,
    /// `MerlTable::lookup_interpolated` itself, on the channel-major table (slower; for
    /// comparisons).
    InterpolatedReference,
    /// The containing cell's value, `MerlTable::lookup_nearest` (MERL's reference reader).
    Nearest,
}

/// How directions are drawn for a tabulated BRDF.
#[derive(Clone, Debug)]
pub enum MerlSampling {
    /// From the table's own values ([`TableSampler`]; the default).
    Table(Arc<TableSampler>),
    /// From a fitted analytic proxy ([`SamplingLobe`]).
    Lobe(SamplingLobe),
}

/// A measured BRDF given by a borrowed MERL table.
#[derive(Clone, Debug)]
pub struct MerlBrdf<'a> {
    table: &'a MerlTable,
    /// The interleaved copy, present when `lookup` is [`MerlLookup::Interpolated`].
    fast: Option<Arc<InterleavedTable>>,
    lookup: MerlLookup,
    sampling: MerlSampling,
}

impl<'a> MerlBrdf<'a> {
    /// The BRDF of `table`, interpolated, sampled from its own values ([`TableSampler`], built
    /// here from the interpolated lookups, about 0.5 M of them). Makes an interleaved copy of the
    /// table (17.5 MB).
    pub fn new(table: &'a MerlTable) -> Self {
        let fast = Arc::new(InterleavedTable::new(table));
        let sampler = TableSampler::new(|wi, wo| {
            fast.lookup_interpolated(wi.to_array(), wo.to_array()).map(|x| f64::from(x.max(0.0)))
        });
        Self {
            table,
            fast: Some(fast),
            lookup: MerlLookup::Interpolated,
            sampling: MerlSampling::Table(Arc::new(sampler)),
        }
    }

    /// The BRDF of `table`, interpolated, sampled by `sampling` (another table's, to draw the
    /// same directions as its renders; no sampler is built).
    pub fn new_sampled(table: &'a MerlTable, sampling: MerlSampling) -> Self {
        Self {
            table,
            fast: Some(Arc::new(InterleavedTable::new(table))),
            lookup: MerlLookup::Interpolated,
            sampling,
        }
    }

    /// The same BRDF looked up by `lookup`.
    pub fn with_lookup(self, lookup: MerlLookup) -> Self {
        let fast = match lookup {
            MerlLookup::Interpolated => {
                self.fast.or_else(|| Some(Arc::new(InterleavedTable::new(self.table))))
            }
            _ => None,
        };
        Self { fast, lookup, ..self }
    }

    /// The same BRDF sampled by `sampling`: renders of two tables that share their sampling
    /// (and a seed) draw the same directions, so their difference carries little Monte Carlo
    /// noise.
    pub fn with_sampling(self, sampling: MerlSampling) -> Self {
        Self { sampling, ..self }
    }

    /// The sampling in use (cheap to clone: the sampler is shared).
    pub fn sampling(&self) -> &MerlSampling {
        &self.sampling
    }

    /// The table.
    pub fn table(&self) -> &'a MerlTable {
        self.table
    }
}

impl Brdf for MerlBrdf<'_> {
    #[inline]
    fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return [0.0; 3];
        }
        let (a, b) = (wi.to_array(), wo.to_array());
        let v = match (&self.fast, self.lookup) {
            (Some(fast), MerlLookup::Interpolated) => fast.lookup_interpolated(a, b),
            (_, MerlLookup::Nearest) => self.table.lookup_nearest(a, b),
            _ => self.table.lookup_interpolated(a, b),
        };
        v.map(|x| f64::from(x.max(0.0)))
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
        match &self.sampling {
            MerlSampling::Table(t) => t.sample(wo, u),
            MerlSampling::Lobe(l) => l.sample(wo, u),
        }
    }

    #[inline]
    fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
        match &self.sampling {
            MerlSampling::Table(t) => t.pdf(wi, wo),
            MerlSampling::Lobe(l) => l.pdf(wi, wo),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::{Ggx, Lambertian, Sum};
    use crate::light::LightSpec;
    use crate::scene::SceneConfig;
    use crate::{render, RenderSettings, Sampler};
    use deepbrdf_data::merl::coords::HalfDiff;
    use deepbrdf_data::merl::grid;
    use deepbrdf_data::Silent;

    /// An analytic BRDF sampled with a given proxy lobe, so that its render draws the same
    /// directions as a [`MerlBrdf`] with that lobe.
    struct WithLobe<B>(B, SamplingLobe);

    impl<B: Brdf> Brdf for WithLobe<B> {
        fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
            self.0.eval(wi, wo)
        }
        fn sample(&self, wo: Vec3, u: [f64; 2]) -> Option<Vec3> {
            self.1.sample(wo, u)
        }
        fn pdf(&self, wi: Vec3, wo: Vec3) -> f64 {
            self.1.pdf(wi, wo)
        }
    }

    /// `brdf` tabulated at the MERL grid's sample angles (phi_h = 0; isotropic).
    fn tabulate(brdf: &impl Brdf) -> MerlTable {
        MerlTable::from_fn(|h, d, p| {
            let angles = HalfDiff {
                theta_h: grid::theta_h_of(h),
                phi_h: 0.0,
                theta_d: grid::theta_d_of(d),
                phi_d: grid::phi_d_of(p),
            };
            let (wi, wo) = angles.to_dirs();
            let f = brdf.eval(Vec3::new(wi[0], wi[1], wi[2]), Vec3::new(wo[0], wo[1], wo[2]));
            f.map(|v| v as f32)
        })
    }

    fn relae(a: &crate::Image, b: &crate::Image) -> f64 {
        let (mut num, mut den) = (0.0, 0.0);
        for (p, q) in a.pixels().iter().zip(b.pixels()) {
            for c in 0..3 {
                num += (f64::from(p[c]) - f64::from(q[c])).abs();
                den += f64::from(q[c]).abs();
            }
        }
        num / den
    }

    #[test]
    fn tabulated_ggx_renders_like_the_analytic_lobe() {
        let analytic =
            Sum::new(Lambertian::new([0.3, 0.2, 0.1]), Ggx::new(0.15, [0.9, 0.6, 0.3]), 0.3);
        let table = tabulate(&analytic);
        // The fitted proxy sees the lobe: a specular mixture weight and about its roughness.
        let lobe = SamplingLobe::fit(&table);
        assert!(lobe.specular_prob > 0.5 && (lobe.alpha / 0.15 - 1.0).abs() < 0.3, "{lobe:?}");
        let merl = MerlBrdf::new(&table).with_sampling(MerlSampling::Lobe(lobe));
        let same_sampling = WithLobe(&analytic, lobe);
        let settings =
            RenderSettings { size: 48, spp: 8, seed: 3, jitter: true, sampler: Sampler::Sobol };
        // Tolerances: the interpolated table errs by a fraction of the lobe's change over one
        // cell (measured RelAE 0.06-0.07%): below 0.5%. The nearest cell errs by up to a
        // cell's change (measured about 3%): below 6%.
        for (light, tol_interp, tol_nearest) in
            [("dir:35,20", 0.005, 0.06), ("sun:40,30", 0.005, 0.06)]
        {
            let scene =
                SceneConfig { light: light.parse::<LightSpec>().unwrap(), ..Default::default() }
                    .build()
                    .unwrap();
            let reference = render(&scene, &same_sampling, &settings, &Silent).unwrap();
            let interp = render(&scene, &merl, &settings, &Silent).unwrap();
            let nearest =
                render(&scene, &merl.clone().with_lookup(MerlLookup::Nearest), &settings, &Silent)
                    .unwrap();
            let (ei, en) = (relae(&interp, &reference), relae(&nearest, &reference));
            assert!(ei < tol_interp, "{light}: interpolated RelAE {ei}");
            assert!(en < tol_nearest, "{light}: nearest RelAE {en}");
            assert!(ei < en, "{light}: interpolation ({ei}) should beat the nearest cell ({en})");
            // The interleaved fast path renders like the data layer's own lookup.
            let data_layer = merl.clone().with_lookup(MerlLookup::InterpolatedReference);
            let slow = render(&scene, &data_layer, &settings, &Silent).unwrap();
            assert!(relae(&interp, &slow) < 1e-5, "{light}: {}", relae(&interp, &slow));
        }
    }

    /// Mean over the image and its standard error, of the per-pixel channel sum of `a - b`
    /// (independent renders: pixel differences are independent).
    fn mean_difference(a: &crate::Image, b: &crate::Image) -> (f64, f64, f64) {
        let sum3 = |p: &[f32; 3]| p.iter().map(|&v| f64::from(v)).sum::<f64>();
        let d: Vec<f64> =
            a.pixels().iter().zip(b.pixels()).map(|(p, q)| sum3(p) - sum3(q)).collect();
        let n = d.len() as f64;
        let mean = d.iter().sum::<f64>() / n;
        let sd = (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let level = b.pixels().iter().map(sum3).sum::<f64>() / n;
        (mean, sd / n.sqrt(), level)
    }

    #[test]
    fn tabulated_ggx_sampled_from_the_table_renders_like_the_analytic_lobe() {
        // Independent sampling (the analytic lobe's own, the table's own): the images agree
        // within their Monte Carlo error under the constant environment and the sun and sky.
        let analytic =
            Sum::new(Lambertian::new([0.3, 0.2, 0.1]), Ggx::new(0.1, [0.9, 0.6, 0.3]), 0.3);
        let table = tabulate(&analytic);
        let merl = MerlBrdf::new(&table);
        let settings =
            RenderSettings { size: 40, spp: 16, seed: 3, jitter: true, sampler: Sampler::Sobol };
        for light in ["const", "sun:40,30"] {
            let scene =
                SceneConfig { light: light.parse::<LightSpec>().unwrap(), ..Default::default() }
                    .build()
                    .unwrap();
            let reference = render(&scene, &analytic, &settings, &Silent).unwrap();
            let tabulated = render(&scene, &merl, &settings, &Silent).unwrap();
            let (mean, se, level) = mean_difference(&tabulated, &reference);
            // 4 standard errors, plus the interpolated table's own error (below 0.5%).
            assert!(
                mean.abs() < 4.0 * se + 0.005 * level,
                "{light}: mean difference {mean} (se {se}, level {level})"
            );
            assert!(se < 0.02 * level, "{light}: se {se} level {level}");
        }
    }
}
