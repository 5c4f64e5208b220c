//! BRDF editing (Hu et al. 2020, §5.1): the edit a user asks for ([`request`]: set or scale the
//! diffuse albedo, the specular albedo or the roughness of a material's 7 [`Attributes`]), and
//! the measures of how well edits, interpolations and sweeps behave ([`measures`]: achieved vs
//! requested change and leakage into the other attributes, uniformity of consecutive image
//! differences, monotonicity of a sweep, physical plausibility of a decoded table; [`lobe`]: the
//! specular lobe read off the table as a person sees it, its floor, peak, width and colour, a
//! dark hole at its centre, and the bars an edit is held to); edits through a representation
//! and its regressor ([`space`]: eq. (7)'s regressor is `deepbrdf_model::regressor`), the
//! analytic edit without any network ([`analytic`]) and the stretch edit, which reshapes the
//! table's own highlight ([`stretch`]), and edits scored against a known answer ([`known`]).
//!
//! [`Attributes`]: crate::attributes::Attributes

pub mod analytic;
pub mod interpolation;
pub mod known;
pub mod lobe;
pub mod measures;
pub mod nearest;
pub mod parts;
pub mod request;
pub mod space;
pub mod stretch;
pub mod suite;

pub use analytic::{analytic_edit, carry_edit};
pub use known::{KnownEdit, KnownTally};
pub use lobe::{
    centre_shift, compare, dark_hole, judge_edit, tinted_centre, verdict, BarCount, EditLobe, Lobe,
    LobeBar, LobeComparison, LobeTally, LobeVerdict,
};
pub use measures::{
    coefficient_of_variation, directional_albedo, edit_outcome, is_monotone, plausibility,
    EditOutcome, Plausibility,
};
pub use request::{ColourEdit, Edit, EditedAttribute, ScalarEdit};
pub use space::{
    blend, blend_tables, edit_material, path_weights, EditMode, Edited, ModelCodec, Space,
    DEFAULT_LATENT_MODE, DEFAULT_MODE,
};
pub use stretch::{stretch_edit, stretch_roughness};

/// What the editing tests share.
#[cfg(test)]
pub(crate) mod testing {
    use deepbrdf_data::merl::grid::cos_weights;
    use deepbrdf_data::merl::CELLS;
    use deepbrdf_data::MerlTable;

    /// Cosine-weighted relative L1 distance of `a` from `b` over their valid cells.
    pub fn distance(a: &MerlTable, b: &MerlTable) -> f64 {
        let w = cos_weights();
        let (mut num, mut den) = (0.0, 0.0);
        for (n, (&x, &y)) in a.values().iter().zip(b.values()).enumerate() {
            let cell = n % CELLS;
            if x >= 0.0 && y >= 0.0 && w[cell] > 0.0 {
                num += f64::from(w[cell]) * f64::from((x - y).abs());
                den += f64::from(w[cell]) * f64::from(y.abs());
            }
        }
        num / den
    }
}
