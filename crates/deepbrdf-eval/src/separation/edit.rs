//! Edits on Sun et al. 2018's split: the stretch edit ([`crate::editing::stretch_edit`]) with
//! the separation's Lambertian albedo in place of the analytic fit's. The fit explains a table
//! as one Lambertian + GGX pair, so a broad glow under a sharp highlight (a metallic paint's)
//! is taken for part of the lobe and the fit finds no diffuse to edit; the separation picks the
//! albedo at which the collection's specular parts explain the rest of the table (Sun et al.
//! 2018, §4), which is the decomposition an edit of the diffuse part needs. The roughness edit
//! then stretches only what lies above that floor, and an albedo edit moves only it.

use super::{SeparatedBasis, SeparationConfig, NAME};
use crate::attributes::Attributes;
use crate::error::Result;
use deepbrdf_data::{MerlTable, Progress};

/// The separation fitted to `train` for splitting tables: the default settings; of the
/// representation it also builds, one specular component is kept (a split needs only its
/// search basis).
pub fn fit_split(train: &[&MerlTable], progress: &dyn Progress) -> Result<SeparatedBasis> {
    SeparatedBasis::fit(NAME, &SeparationConfig::default(), train, 1, progress)
}

/// The fitted attributes `fitted` of `table` with the diffuse albedo the separation finds
/// (each channel in [0, 1], the range of an attribute): the attributes an edit on the split
/// starts from, made by [`crate::editing::stretch_edit`] from them.
pub fn separated_attributes(
    basis: &SeparatedBasis,
    table: &MerlTable,
    fitted: &Attributes,
) -> Attributes {
    Attributes { diffuse: basis.separate(table).map(|a| a.clamp(0.0, 1.0)), ..*fitted }
}
