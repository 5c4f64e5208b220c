//! What the editor makes of an edit request (§5.1): its [`Plan`] (the material or blend it
//! starts from, the attributes asked for and, for the modes that edit the latent, the edited
//! latent), then the edited table: the decoded latent (kept per latent), or the table edited
//! itself by the other modes (transfer, analytic, stretch, parts; kept per edit).
use super::{Editor, Material};
use crate::editing::{self, EditMode, ModelCodec, Space};
use crate::serve::replies::{internal, Failure};
use crate::serve::request::{CheckedEdit, Refusal};
use deepbrdf_data::MerlTable;
use deepbrdf_eval::attributes::Attributes;
use deepbrdf_eval::editing::parts::parts_edit;
use std::sync::Arc;

/// An edit worked out up to its table.
pub(super) struct Plan {
    /// The latent the edit starts from: the material's, or the blend of two materials'.
    pub start: Vec<f32>,
    /// The edited latent (paper and residual edits); none for the modes that edit the table.
    pub latent: Option<Vec<f32>>,
    /// The attributes of the (blended) material the edit starts from.
    pub base: Attributes,
    /// The attributes asked for.
    pub requested: Attributes,
    pub material: Arc<Material>,
}

impl Editor {
    /// The latent, attributes and material the edit starts from: the material's, or the latent
    /// blend of two materials with the blend of their attributes.
    fn base(
        &mut self,
        edit: &CheckedEdit,
    ) -> Result<(Vec<f32>, Attributes, Arc<Material>), Failure> {
        let a = self.material(&edit.material)?;
        let Some((other, t)) = &edit.blend else {
            return Ok((a.latent.clone(), a.attributes, a));
        };
        let b = self.material(other)?;
        let attributes = a.attributes.blend(&b.attributes, *t);
        Ok((editing::blend(&a.latent, &b.latent, *t), attributes, a))
    }

    /// The edit's plan: its base and the attributes asked for and, for a mode that edits the
    /// latent, the regressor's edited latent.
    pub(super) fn plan(&mut self, edit: &CheckedEdit) -> Result<Plan, Failure> {
        let (start, base, material) = self.base(edit)?;
        let requested = edit.edit.apply(&base).map_err(|e| Refusal::BadRequest(e.to_string()))?;
        let latent = match EditMode::LATENT.contains(&edit.mode) {
            true => {
                let codec = ModelCodec(&self.model);
                let space = Space { codec: &codec, regressor: &self.regressor };
                Some(space.edited_latent(&start, &base, &requested, edit.mode)?)
            }
            false => None,
        };
        Ok(Plan { start, latent, base, requested, material })
    }

    /// The edited table of `plan`: its latent decoded, or the table edited by a mode that edits
    /// the table itself ([`Space::edit`], from the material's table or the linear blend of the
    /// two materials' tables).
    pub(super) fn table(
        &mut self,
        edit: &CheckedEdit,
        plan: &Plan,
    ) -> Result<Arc<MerlTable>, Failure> {
        if let Some(z) = &plan.latent {
            return self.decoded(z);
        }
        let key = format!("{:?}", (&edit.material, &edit.blend, edit.mode.name(), &edit.edit));
        if let Some(t) = self.edited.get(&key) {
            return Ok(t);
        }
        let blended = match &edit.blend {
            None => None,
            Some((other, t)) => {
                let b = self.material(other)?;
                Some(editing::blend_tables(&plan.material.table, &b.table, *t)?)
            }
        };
        let codec = ModelCodec(&self.model);
        let space = Space { codec: &codec, regressor: &self.regressor };
        let table = blended.as_ref().unwrap_or(&plan.material.table);
        let edited = match (edit.mode, &blended) {
            // A material's parts are fitted once and kept.
            (EditMode::Parts, None) => {
                parts_edit(table, plan.material.parts()?, &plan.base, &plan.requested)?
            }
            _ => space.edit(table, &plan.start, &plan.base, &edit.edit, edit.mode)?.table,
        };
        let table = Arc::new(edited);
        self.edited.put(key, table.clone());
        Ok(table)
    }

    /// The decoded table of a latent (kept for the next request with the same latent: the
    /// refined preview, a download).
    fn decoded(&mut self, z: &[f32]) -> Result<Arc<MerlTable>, Failure> {
        let key: Vec<u32> = z.iter().map(|v| v.to_bits()).collect();
        if let Some(t) = self.decoded.get(&key) {
            return Ok(t);
        }
        let table = Arc::new(self.model.decode(z).map_err(internal)?);
        self.decoded.put(key, table.clone());
        Ok(table)
    }
}
