//! The known-answer suite (`experiments edit-known`): analytic corpus materials
//! ([`deepbrdf_data::corpus`], drawn with a seed no network was trained on) edited as a user
//! would edit them: their attributes fitted, then roughness x0.5 and x2, diffuse and specular
//! albedo x0.5 and a recolour (the diffuse channels rotated) asked of the fit. The answer is
//! the same material with the parameter changed; each method's edit is scored by its distance
//! to the answer against the unedited material's ([`super::distances`]).

use super::{albedo_error, albedos, distances, KnownEdit};
use crate::attributes::{self, Attributes, FitConfig};
use crate::editing::parts::{fit_parts, parts_edit, Parts, PartsConfig};
use crate::editing::{
    judge_edit, stretch_edit, ColourEdit, Edit, EditMode, Lobe, ScalarEdit, Space,
};
use crate::error::{EvalError, Result};
use crate::metrics::ImageRelaeConfig;
use crate::separation::{separated_attributes, SeparatedBasis};
use deepbrdf_data::corpus::{self, Material};
use deepbrdf_data::{MerlTable, Progress};
use std::str::FromStr;

/// A method that edits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KnownMethod {
    /// The analytic edit, no network ([`crate::editing::analytic`]).
    Analytic,
    /// The stretch edit, no network ([`crate::editing::stretch`]).
    Stretch,
    /// DeepBRDF's residual edit.
    DeepbrdfResidual,
    /// DeepBRDF's edit of the paper.
    DeepbrdfPaper,
    /// DeepBRDF's nearest latent edit ([`crate::editing::nearest`]).
    DeepbrdfNearest,
    /// IPCA's residual edit.
    IpcaResidual,
    /// DeepBRDF's residual edit carried onto the table ([`Space::transfer`]).
    DeepbrdfTransfer,
    /// DeepBRDF's edit of the paper carried onto the table.
    DeepbrdfTransferPaper,
    /// IPCA's residual edit carried onto the table.
    IpcaTransfer,
    /// The parts edit, no network ([`crate::editing::parts`]).
    Parts,
    /// The stretch edit on Sun et al. 2018's diffuse-specular split
    /// ([`crate::separation::separated_attributes`]).
    Sun2018Stretch,
}

deepbrdf_data::named_enum!(KnownMethod {
    Analytic => "analytic",
    Stretch => "stretch",
    Parts => "parts",
    DeepbrdfResidual => "deepbrdf-residual",
    DeepbrdfPaper => "deepbrdf-paper",
    DeepbrdfNearest => "deepbrdf-nearest",
    IpcaResidual => "ipca-residual",
    DeepbrdfTransfer => "deepbrdf-transfer",
    DeepbrdfTransferPaper => "deepbrdf-transfer-paper",
    IpcaTransfer => "ipca-transfer",
    Sun2018Stretch => "sun2018-stretch",
});

impl FromStr for KnownMethod {
    type Err = EvalError;
    fn from_str(s: &str) -> Result<Self> {
        Self::from_name(s).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|m| m.name()).collect();
            EvalError::Invalid(format!("unknown edit method '{s}' ({})", names.join(", ")))
        })
    }
}

impl KnownMethod {
    /// Whether the method edits through IPCA.
    pub fn ipca(self) -> bool {
        matches!(self, Self::IpcaResidual | Self::IpcaTransfer)
    }

    /// Whether the method edits through DeepBRDF.
    pub fn deepbrdf(self) -> bool {
        matches!(
            self,
            Self::DeepbrdfResidual
                | Self::DeepbrdfPaper
                | Self::DeepbrdfNearest
                | Self::DeepbrdfTransfer
                | Self::DeepbrdfTransferPaper
        )
    }

    /// The method's edit mode.
    fn mode(self) -> EditMode {
        match self {
            Self::Analytic => EditMode::Analytic,
            Self::Stretch | Self::Sun2018Stretch => EditMode::Stretch,
            Self::Parts => EditMode::Parts,
            Self::DeepbrdfResidual | Self::IpcaResidual => EditMode::Residual,
            Self::DeepbrdfPaper | Self::DeepbrdfTransferPaper => EditMode::Paper,
            Self::DeepbrdfNearest => EditMode::Nearest,
            Self::DeepbrdfTransfer | Self::IpcaTransfer => EditMode::Transfer,
        }
    }

    /// The method's name in the results.
    pub fn label(self) -> &'static str {
        match self {
            Self::Analytic => "analytic",
            Self::Stretch => "stretch",
            Self::Parts => "parts",
            Self::DeepbrdfResidual => "DeepBRDF residual",
            Self::DeepbrdfPaper => "DeepBRDF paper",
            Self::DeepbrdfNearest => "DeepBRDF nearest",
            Self::IpcaResidual => "IPCA residual",
            Self::DeepbrdfTransfer => "DeepBRDF transfer",
            Self::DeepbrdfTransferPaper => "DeepBRDF transfer (paper)",
            Self::IpcaTransfer => "IPCA transfer",
            Self::Sun2018Stretch => "stretch on Sun2018's split",
        }
    }
}

/// The suite's recolour: the diffuse channels rotated, asked of the albedo an edit starts from.
pub const RECOLOUR: &str = "recolour";

/// One edit of the suite: its name, the edit asked of the fitted attributes, and the answer.
pub struct Case {
    pub name: &'static str,
    pub edit: Edit,
    pub answer: Material,
}

/// The suite's edits of `material` (fitted attributes `fitted`).
pub fn cases(material: &Material, fitted: &Attributes) -> Vec<Case> {
    let known = material.attributes().diffuse;
    let scale = |s: f64| Some(ColourEdit::Scale(s));
    vec![
        Case {
            name: "roughness x0.5",
            edit: Edit { roughness: Some(ScalarEdit::Scale(0.5)), ..Edit::default() },
            answer: material.roughness_scaled(0.5),
        },
        Case {
            name: "roughness x2",
            edit: Edit { roughness: Some(ScalarEdit::Scale(2.0)), ..Edit::default() },
            answer: material.roughness_scaled(2.0),
        },
        Case {
            name: "diffuse x0.5",
            edit: Edit { diffuse: scale(0.5), ..Edit::default() },
            answer: material.diffuse_scaled(0.5),
        },
        Case {
            name: "specular x0.5",
            edit: Edit { specular: scale(0.5), ..Edit::default() },
            answer: material.specular_scaled(0.5),
        },
        Case {
            name: RECOLOUR,
            edit: Edit::rotated_diffuse(fitted.diffuse),
            answer: material.recoloured([known[2], known[0], known[1]]),
        },
    ]
}

/// Whether the answer is the edit asked: the attributes changed (an albedo edit of a material
/// without that component, or a recolour of a grey, changes nothing) and no clamp bound
/// (roughness x2 of alpha 0.8).
pub fn answer_is_exact(material: &Material, case: &Case) -> bool {
    let (a, b) = (material.attributes(), case.answer.attributes());
    if a == b {
        return false;
    }
    match case.edit.roughness {
        Some(ScalarEdit::Scale(s)) => (b.roughness - a.roughness * s).abs() <= 1e-9 * a.roughness,
        _ => true,
    }
}

/// What the suite runs.
pub struct KnownInput<'a> {
    /// Corpus materials `0..count` of the corpus drawn with `seed`.
    pub count: u64,
    pub seed: u64,
    /// The methods, in the order of the results.
    pub methods: &'a [KnownMethod],
    /// The representations the network methods edit through, where they are asked for.
    pub deepbrdf: Option<Space<'a>>,
    pub ipca: Option<Space<'a>>,
    /// Sun et al. 2018's split, for [`KnownMethod::Sun2018Stretch`].
    pub separation: Option<&'a SeparatedBasis>,
}

/// The suite's result: a row per edit and method, and the edits left out because their answer
/// is not the edit asked ([`answer_is_exact`]).
pub struct KnownRun {
    pub rows: Vec<KnownEdit>,
    pub skipped: usize,
}

/// Runs the suite (see the module's documentation); an error names the material and edit.
pub fn run(input: &KnownInput, progress: &dyn Progress) -> Result<KnownRun> {
    let missing = input.methods.iter().find(|m| {
        (m.deepbrdf() && input.deepbrdf.is_none())
            || (m.ipca() && input.ipca.is_none())
            || (**m == KnownMethod::Sun2018Stretch && input.separation.is_none())
    });
    if let Some(m) = missing {
        return Err(EvalError::Invalid(format!(
            "the {} edit's representation was not given",
            m.name()
        )));
    }
    let fit = FitConfig::default();
    let config = ImageRelaeConfig::default();
    let mut run = KnownRun { rows: Vec::new(), skipped: 0 };
    progress.start(input.count, "known-answer edits");
    for index in 0..input.count {
        let material = corpus::sample(input.seed, index);
        let name = format!("{index:03}-{}", material.family);
        let context = |what: &str, e: EvalError| EvalError::Invalid(format!("{name}{what}: {e}"));
        let table = material.table().map_err(|e| context(", tabulating", e.into()))?;
        let fitted = attributes::fit(&table, &fit).map_err(|e| context(", fitting", e))?.attributes;
        let subject = Subject::new(input, &table, &fitted)?;
        for case in cases(&material, &fitted) {
            if case.edit.apply(&fitted).is_err() || !answer_is_exact(&material, &case) {
                run.skipped += 1;
                continue;
            }
            let in_case = |e: EvalError| context(&format!(" {}", case.name), e);
            let answer = case.answer.table().map_err(|e| in_case(e.into()))?;
            let answer_albedos = albedos(&answer);
            let tables = input
                .methods
                .iter()
                .map(|&m| subject.edit(m, &case).map_err(in_case))
                .collect::<Result<Vec<MerlTable>>>()?;
            let refs: Vec<&MerlTable> = tables.iter().collect();
            let (unedited, edited) = distances(&answer, &table, &refs, &config).map_err(in_case)?;
            for ((method, t), edited) in input.methods.iter().zip(&tables).zip(edited) {
                let judged = subject.lobe.as_ref().and_then(|o| judge_edit(o, t, &case.edit).ok());
                run.rows.push(KnownEdit {
                    material: name.clone(),
                    edit: case.name.into(),
                    method: method.label().into(),
                    unedited,
                    edited,
                    dark_hole: judged.map(|l| l.comparison.dark_hole),
                    albedo_error: albedo_error(&answer_albedos, t),
                });
            }
        }
        progress.advance(1);
    }
    progress.finish();
    Ok(run)
}

/// One corpus material as the methods edit it: its table, fit, latents and split.
struct Subject<'a> {
    input: &'a KnownInput<'a>,
    table: &'a MerlTable,
    fitted: &'a Attributes,
    deep_latent: Option<Vec<f32>>,
    ipca_latent: Option<Vec<f32>>,
    split: Option<Attributes>,
    parts: Option<Parts>,
    lobe: Option<Lobe>,
}

impl<'a> Subject<'a> {
    fn new(
        input: &'a KnownInput<'a>,
        table: &'a MerlTable,
        fitted: &'a Attributes,
    ) -> Result<Self> {
        let wants = |f: fn(KnownMethod) -> bool| input.methods.iter().any(|&m| f(m));
        let latent = |space: &Option<Space>, wanted: bool| match (space, wanted) {
            (Some(s), true) => s.codec.encode(table).map(Some),
            _ => Ok(None),
        };
        Ok(Self {
            input,
            table,
            fitted,
            deep_latent: latent(&input.deepbrdf, wants(KnownMethod::deepbrdf))?,
            ipca_latent: latent(&input.ipca, wants(KnownMethod::ipca))?,
            split: input.separation.map(|b| separated_attributes(b, table, fitted)),
            parts: match wants(|m| m == KnownMethod::Parts) {
                true => Some(fit_parts(table, &PartsConfig::default())?.parts),
                false => None,
            },
            lobe: Lobe::of(table).ok(),
        })
    }

    /// The table edited by `method` as `case` asks.
    fn edit(&self, method: KnownMethod, case: &Case) -> Result<MerlTable> {
        let (table, fitted) = (self.table, self.fitted);
        let missing = || EvalError::Invalid(format!("the {} edit's representation", method.name()));
        if method == KnownMethod::Parts {
            // The recolour rotates the floor's albedo, the parts' diffuse.
            let parts = self.parts.as_ref().ok_or_else(missing)?;
            let (start, edit) = match case.name {
                RECOLOUR => {
                    let start = Attributes { diffuse: parts.floor.albedo, ..*fitted };
                    (start, Edit::rotated_diffuse(start.diffuse))
                }
                _ => (*fitted, case.edit),
            };
            return parts_edit(table, parts, &start, &edit.apply(&start)?);
        }
        if method == KnownMethod::Sun2018Stretch {
            let split = self.split.as_ref().ok_or_else(missing)?;
            let edit = match case.name {
                RECOLOUR => Edit::rotated_diffuse(split.diffuse),
                _ => case.edit,
            };
            return stretch_edit(table, split, &edit.apply(split)?);
        }
        let (space, latent) = match method.ipca() {
            true => (self.input.ipca.as_ref(), self.ipca_latent.as_ref()),
            false => (self.input.deepbrdf.as_ref(), self.deep_latent.as_ref()),
        };
        let (space, latent) = match method.mode().needs_network() {
            true => (space.ok_or_else(missing)?, latent.ok_or_else(missing)?.as_slice()),
            false => {
                let requested = case.edit.apply(fitted)?;
                return method.mode().edit_without_network(table, fitted, &requested);
            }
        };
        Ok(match method {
            KnownMethod::DeepbrdfTransferPaper => {
                space.transfer(table, latent, fitted, &case.edit, EditMode::Paper)?
            }
            _ => space.edit(table, latent, fitted, &case.edit, method.mode())?,
        }
        .table)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::corpus::Family;
    use deepbrdf_data::Silent;

    #[test]
    fn cases_name_exact_answers_and_skip_clamped_ones() {
        let material = corpus::sample_family(Family::Plastic, 1, 0);
        let fitted = Attributes { diffuse: [0.2, 0.3, 0.4], specular: [0.04; 3], roughness: 0.1 };
        // A plastic has every component: each edit changes it, none clamps at this roughness.
        let plastic = material.roughness_scaled(0.1 / material.attributes().roughness);
        let all = cases(&plastic, &fitted);
        assert_eq!(all.len(), 5);
        assert!(all.iter().all(|c| answer_is_exact(&plastic, c)), "{plastic:?}");
        // A metal has no diffuse base: its diffuse edits change nothing.
        let metal = corpus::sample_family(Family::Metal, 1, 0);
        let edits = cases(&metal, &fitted);
        assert!(!answer_is_exact(&metal, &edits[2]) && !answer_is_exact(&metal, &edits[4]));
        // Every alpha at the top of its range: x2 clamps, so its answer is not the edit asked.
        let rough = material.roughness_scaled(1e6);
        assert!(!answer_is_exact(&rough, &cases(&rough, &fitted)[1]));
        assert!(answer_is_exact(&rough, &cases(&rough, &fitted)[0]));
    }

    #[test]
    fn a_network_method_without_its_representation_is_refused() {
        let input = KnownInput {
            count: 1,
            seed: 0,
            methods: &[KnownMethod::Analytic, KnownMethod::IpcaResidual],
            deepbrdf: None,
            ipca: None,
            separation: None,
        };
        let err = run(&input, &Silent).err().expect("refused").to_string();
        assert!(err.contains("ipca-residual"), "{err}");
        assert_eq!("Sun2018-Stretch".parse::<KnownMethod>().unwrap(), KnownMethod::Sun2018Stretch);
        assert!("pca".parse::<KnownMethod>().is_err());
    }
}
