//! Edits and interpolations through a representation (Hu et al. 2020, §5.1): a [`Codec`] (a
//! DeepBRDF model or an IPCA basis) and the regressor of eq. (7) trained for it. The paper's
//! edit is `Y' = Phi(alpha')`; the residual edit `Y' = Y + Phi(alpha') - Phi(alpha)` keeps
//! what the attributes do not explain; interpolation blends two latents (or, as the reference
//! path, two tables).

use crate::attributes::Attributes;
use crate::editing::nearest::AttributePredictor;
use crate::editing::parts::{fit_and_edit, Parts};
use crate::editing::{analytic_edit, carry_edit, stretch_edit, Edit};
use crate::error::{EvalError, Result};
use crate::harness::Codec;
use deepbrdf_data::merl::INVALID_VALUE;
use deepbrdf_data::MerlTable;
use deepbrdf_model::regressor::Regressor;
use deepbrdf_model::DeepBrdf;
use std::fmt;
use std::str::FromStr;

/// Which edit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EditMode {
    /// The paper's edit: the latent of the edited attributes, `Y' = Phi(alpha')`.
    Paper,
    /// Keeps what the attributes do not explain: `Y' = Y + Phi(alpha') - Phi(alpha)`.
    Residual,
    /// The latent nearest the material's whose attributes, as a linear latent-to-attribute
    /// predictor reads them, change as asked ([`crate::editing::nearest`]).
    Nearest,
    /// The residual edit's change `D(Y) -> D(Y')` carried onto the table itself
    /// ([`Space::transfer`]): what the representation does not reconstruct is kept.
    Transfer,
    /// The analytic edit, no network ([`crate::editing::analytic_edit`]).
    Analytic,
    /// The stretch edit, no network: the roughness by reshaping the table's own highlight,
    /// the albedos as the analytic edit ([`crate::editing::stretch_edit`]).
    Stretch,
    /// The parts edit, no network: the table split into a floor, lobes, a retro-reflective
    /// ridge and a sheen, each lobe stretched by its own roughness and the floor scaled
    /// ([`crate::editing::parts`]).
    Parts,
}

impl EditMode {
    /// Every mode.
    pub const ALL: [EditMode; 7] = [
        EditMode::Paper,
        EditMode::Residual,
        EditMode::Nearest,
        EditMode::Transfer,
        EditMode::Analytic,
        EditMode::Stretch,
        EditMode::Parts,
    ];
    /// The modes whose result is a latent, decoded as it is (the browser editor's).
    pub const LATENT: [EditMode; 3] = [EditMode::Paper, EditMode::Residual, EditMode::Nearest];

    /// The mode's name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::Residual => "residual",
            Self::Nearest => "nearest",
            Self::Transfer => "transfer",
            Self::Analytic => "analytic",
            Self::Stretch => "stretch",
            Self::Parts => "parts",
        }
    }

    /// Whether the edit needs the table's latent (its encoding).
    pub fn needs_latent(self) -> bool {
        matches!(self, Self::Residual | Self::Transfer | Self::Nearest)
    }

    /// Whether the edit goes through a representation and its regressor.
    pub fn needs_network(self) -> bool {
        !matches!(self, Self::Analytic | Self::Stretch | Self::Parts)
    }

    /// The edit of a mode without a network: `table`, fitted to `original`, edited to
    /// `requested`; an error for the modes through a representation.
    pub fn edit_without_network(
        self,
        table: &MerlTable,
        original: &Attributes,
        requested: &Attributes,
    ) -> Result<MerlTable> {
        match self {
            Self::Analytic => analytic_edit(table, original, requested),
            Self::Stretch => stretch_edit(table, original, requested),
            Self::Parts => Ok(fit_and_edit(table, original, requested)?.0),
            Self::Paper | Self::Residual | Self::Transfer | Self::Nearest => {
                Err(EvalError::Invalid(format!("the {self} edit needs a model and its regressor")))
            }
        }
    }
}

impl fmt::Display for EditMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for EditMode {
    type Err = EvalError;

    fn from_str(s: &str) -> Result<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s.trim()).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|m| m.name()).collect();
            EvalError::Invalid(format!("edit mode {s:?}: expected one of {}", names.join(", ")))
        })
    }
}

/// The default edit of a table (`experiments edit`, `Model.edit`, the browser editor's page):
/// the parts edit, the one that reaches the known answers of generated materials of every
/// family, widens and narrows held-out measured highlights as asked most often, and keeps a
/// retro-reflective ridge and a sheen where they are (docs/editing.md has the measured
/// comparison).
pub const DEFAULT_MODE: EditMode = EditMode::Parts;

/// The default latent edit (`bench edit`, and the browser editor's API when a request names no
/// mode): the residual edit, which keeps an unedited material as it is, as the paper's edit
/// does not.
pub const DEFAULT_LATENT_MODE: EditMode = EditMode::Residual;

/// A DeepBRDF model borrowed as a [`Codec`] (eq. (2) to encode, eq. (3) to decode), mapping
/// each table as it comes (the harness' [`crate::deep::DeepCodec`] caches the mapping instead).
pub struct ModelCodec<'a>(pub &'a DeepBrdf);

impl Codec for ModelCodec<'_> {
    fn name(&self) -> String {
        format!("DeepBRDF-{}", self.0.k())
    }

    fn k(&self) -> usize {
        self.0.k()
    }

    fn encode(&self, table: &MerlTable) -> Result<Vec<f32>> {
        self.0.encode(table).map_err(|e| EvalError::method(self.name(), e))
    }

    fn decode(&self, code: &[f32]) -> Result<MerlTable> {
        self.0.decode(code).map_err(|e| EvalError::method(self.name(), e))
    }
}

/// A representation and its regressor.
pub struct Space<'a> {
    pub codec: &'a dyn Codec,
    pub regressor: &'a Regressor,
}

/// An edit's result.
pub struct Edited {
    /// The attributes asked for.
    pub requested: Attributes,
    pub table: MerlTable,
    /// The table's parts, where the parts edit made it.
    pub parts: Option<Parts>,
}

impl Space<'_> {
    /// Eq. (7): the latent of `a`.
    pub fn latent_of(&self, a: &Attributes) -> Result<Vec<f32>> {
        self.regressor
            .predict(&a.to_array())
            .map_err(|e| EvalError::method(format!("{} regressor", self.codec.name()), e))
    }

    /// Edits `table`, whose attributes are `original` (and latent `latent`, which the residual
    /// and transfer edits need), by `edit` in `mode`.
    pub fn edit(
        &self,
        table: &MerlTable,
        latent: &[f32],
        original: &Attributes,
        edit: &Edit,
        mode: EditMode,
    ) -> Result<Edited> {
        let requested = edit.apply(original)?;
        let table = match mode {
            EditMode::Paper | EditMode::Residual | EditMode::Nearest => {
                self.codec.decode(&self.edited_latent(latent, original, &requested, mode)?)?
            }
            EditMode::Transfer => return self.transfer(table, latent, original, edit, mode),
            EditMode::Analytic | EditMode::Stretch | EditMode::Parts => {
                mode.edit_without_network(table, original, &requested)?
            }
        };
        Ok(Edited { requested, table, parts: None })
    }

    /// The transfer edit: the representation's change carried onto `table` itself
    /// ([`carry_edit`]) instead of replacing the table by a decoded one. With `mode` paper it
    /// carries the change from `D(Phi(alpha))` to `D(Phi(alpha'))`; otherwise the residual
    /// edit's, from the table's reconstruction `D(Y)` to `D(Y')`. What the representation does not
    /// reconstruct of the unedited table is kept, as the analytic edit keeps what its model does
    /// not explain.
    pub fn transfer(
        &self,
        table: &MerlTable,
        latent: &[f32],
        original: &Attributes,
        edit: &Edit,
        mode: EditMode,
    ) -> Result<Edited> {
        let requested = edit.apply(original)?;
        if requested == *original {
            return Ok(Edited { requested, table: table.clone(), parts: None });
        }
        let (before, mode) = match mode {
            EditMode::Paper => (self.codec.decode(&self.latent_of(original)?)?, EditMode::Paper),
            _ => (self.codec.decode(latent)?, EditMode::Residual),
        };
        let after = self.codec.decode(&self.edited_latent(latent, original, &requested, mode)?)?;
        let table = carry_edit(table, &before, &after)?;
        Ok(Edited { requested, table, parts: None })
    }

    /// The latent of the edit from `original` (latent `latent`, used by the residual edit) to
    /// the attributes `requested` (checked by [`Edit::apply`]), before decoding. The transfer
    /// edit's latent is the residual edit's; the analytic edit has none (an error).
    pub fn edited_latent(
        &self,
        latent: &[f32],
        original: &Attributes,
        requested: &Attributes,
        mode: EditMode,
    ) -> Result<Vec<f32>> {
        if mode == EditMode::Nearest {
            return AttributePredictor::of(self.regressor)?.nearest(latent, original, requested);
        }
        let target = self.latent_of(requested)?;
        Ok(match mode {
            EditMode::Paper => target,
            EditMode::Analytic | EditMode::Stretch | EditMode::Parts => {
                return Err(EvalError::Invalid(format!("the {mode} edit has no latent")));
            }
            EditMode::Residual | EditMode::Transfer | EditMode::Nearest => {
                let base = self.latent_of(original)?;
                latent.iter().zip(target.iter().zip(&base)).map(|(y, (t, b))| y + t - b).collect()
            }
        })
    }
}

/// One material's edit as `experiments edit` and the Python package make it: `table` (whose
/// attributes are `original`) edited by `edit` in `mode`, analytically (no network) or through
/// `editor`, a DeepBRDF model and its regressor (eq. 7), encoding the table first when the mode
/// needs its latent. An error when the mode needs a network and none is given.
pub fn edit_material(
    table: &MerlTable,
    original: &Attributes,
    edit: &Edit,
    mode: EditMode,
    editor: Option<(&DeepBrdf, &Regressor)>,
) -> Result<Edited> {
    match (mode.needs_network(), editor) {
        (false, _) => {
            let requested = edit.apply(original)?;
            if mode == EditMode::Parts {
                let (table, parts) = fit_and_edit(table, original, &requested)?;
                return Ok(Edited { requested, table, parts: Some(parts) });
            }
            let table = mode.edit_without_network(table, original, &requested)?;
            Ok(Edited { requested, table, parts: None })
        }
        (true, Some((model, regressor))) => {
            let codec = ModelCodec(model);
            let space = Space { codec: &codec, regressor };
            let latent = match mode.needs_latent() {
                true => codec.encode(table)?,
                false => Vec::new(),
            };
            space.edit(table, &latent, original, edit, mode)
        }
        (true, None) => {
            Err(EvalError::Invalid(format!("the {mode} edit needs a model and its regressor")))
        }
    }
}

/// The `steps` blend weights of an interpolation path, both ends included: `t = i / (steps -
/// 1)` (Fig. 10).
pub fn path_weights(steps: usize) -> Vec<f64> {
    (0..steps).map(|i| i as f64 / (steps.max(2) - 1) as f64).collect()
}

/// `(1 - t) a + t b`.
pub fn blend(a: &[f32], b: &[f32], t: f64) -> Vec<f32> {
    a.iter().zip(b).map(|(&x, &y)| ((1.0 - t) * f64::from(x) + t * f64::from(y)) as f32).collect()
}

/// The plain linear blend of two tables (the reference path of interpolation): valid cells of
/// both blended, the others invalid.
pub fn blend_tables(a: &MerlTable, b: &MerlTable, t: f64) -> Result<MerlTable> {
    let values: Vec<f32> = a
        .values()
        .iter()
        .zip(b.values())
        .map(|(&x, &y)| match x < 0.0 || y < 0.0 {
            true => INVALID_VALUE,
            false => ((1.0 - t) * f64::from(x) + t * f64::from(y)) as f32,
        })
        .collect();
    Ok(MerlTable::from_values(values)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::editing::ScalarEdit;
    use deepbrdf_data::testing::synthetic_table;

    #[test]
    fn modes_parse_by_name() {
        for m in EditMode::ALL {
            assert_eq!(m.name().parse::<EditMode>().unwrap(), m);
        }
        assert!("linear".parse::<EditMode>().unwrap_err().to_string().contains("analytic"));
        assert!(EditMode::LATENT.iter().all(|m| m.needs_network()));
        assert!(!EditMode::Analytic.needs_network() && !EditMode::Paper.needs_latent());
    }

    #[test]
    fn path_weights_run_from_zero_to_one() {
        assert_eq!(path_weights(5), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        assert_eq!(path_weights(2), vec![0.0, 1.0]);
    }

    #[test]
    fn a_material_edit_needs_a_network_unless_analytic() {
        let table = synthetic_table(3);
        let original = Attributes { diffuse: [0.3, 0.2, 0.1], specular: [0.05; 3], roughness: 0.1 };
        let edit = Edit { roughness: Some(ScalarEdit::Scale(2.0)), ..Edit::default() };
        let Err(err) = edit_material(&table, &original, &edit, EditMode::Residual, None) else {
            panic!("a residual edit without a model was made");
        };
        assert!(err.to_string().contains("needs a model"), "{err}");
        let analytic = edit_material(&table, &original, &edit, EditMode::Analytic, None).unwrap();
        assert_eq!(analytic.requested.roughness, 0.2);
        let direct = analytic_edit(&table, &original, &analytic.requested).unwrap();
        assert_eq!(analytic.table, direct);
    }

    #[test]
    fn blends_are_linear_and_keep_invalid_cells() {
        assert_eq!(blend(&[0.0, 2.0], &[1.0, 4.0], 0.25), vec![0.25, 2.5]);
        let (a, mut b) = (synthetic_table(1), synthetic_table(2));
        let cell = a.values().iter().position(|&v| v >= 0.0).unwrap();
        b.values_mut()[cell] = INVALID_VALUE;
        let mid = blend_tables(&a, &b, 0.5).unwrap();
        assert_eq!(mid.values()[cell], INVALID_VALUE);
        assert_eq!(blend_tables(&a, &b, 0.0).unwrap().values()[cell + 1], a.values()[cell + 1]);
        let (x, y) = (a.values()[cell + 1], b.values()[cell + 1]);
        let m = mid.values()[cell + 1];
        assert!((f64::from(m) - 0.5 * (f64::from(x) + f64::from(y))).abs() < 1e-6);
    }
}
