//! The requests of the browser editor (`experiments serve`) as the page sends them (JSON), and
//! their checked form: a material id that names a bundled material or an upload (never a
//! path), the 7 attributes as an [`Edit`] (checked against the material by [`Edit::apply`],
//! the editing library's validation), a blend weight in [0, 1], and the preview scene (shape,
//! sun position, turbidity) built into a [`SceneConfig`].
use crate::editing::{EditMode, DEFAULT_LATENT_MODE};
use deepbrdf_data::bundled::Collection;
use deepbrdf_eval::editing::{ColourEdit, Edit, ScalarEdit};
use deepbrdf_render::{LightSpec, Projection, SceneConfig, Shape};
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

/// The pseudo-collection of uploaded materials: `upload/<digest>`.
pub const UPLOAD_COLLECTION: &str = "upload";
/// Longest material id accepted.
const MAX_ID_CHARS: usize = 120;

/// A request the page got wrong: answered with this status and message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Refusal {
    /// 400: a malformed or out-of-range value, a malformed file.
    BadRequest(String),
    /// 404: no such material.
    NotFound(String),
}

impl Refusal {
    #[cfg(test)]
    pub fn message(&self) -> &str {
        match self {
            Self::BadRequest(m) | Self::NotFound(m) => m,
        }
    }
}

/// `Result` of checking a request.
pub type Checked<T> = Result<T, Refusal>;

fn bad(message: impl Into<String>) -> Refusal {
    Refusal::BadRequest(message.into())
}

/// The bundled materials by id (`merl/chrome`, `rgl-measured/paper_white_rgb`, ...): the only
/// names the server loads (besides its uploads).
pub fn bundled_ids() -> anyhow::Result<Vec<String>> {
    let mut ids = Vec::new();
    for c in Collection::ALL.into_iter().chain([Collection::RglMeasured]) {
        ids.extend(c.names()?.into_iter().map(|n| format!("{}/{n}", c.name())));
    }
    Ok(ids)
}

/// Checks a material id's form: `collection/name` with one slash, no other path separator, no
/// `..`, printable ASCII, at most [`MAX_ID_CHARS`]. Membership is checked by [`Catalogue`].
pub fn check_id(id: &str) -> Checked<()> {
    let printable = id.chars().all(|c| c.is_ascii_graphic());
    if id.is_empty() || id.len() > MAX_ID_CHARS || !printable {
        return Err(bad(format!(
            "material id {id:?}: expected collection/name in printable ASCII, at most \
             {MAX_ID_CHARS} characters"
        )));
    }
    let slashes = id.matches('/').count();
    if id.contains('\\') || id.contains("..") || id.starts_with('/') || slashes != 1 {
        return Err(bad(format!(
            "material id {id:?}: a material is named collection/name (GET /api/materials lists \
             them), never by a path"
        )));
    }
    Ok(())
}

/// The ids the server knows: the bundled materials and the uploads so far.
#[derive(Debug, Clone, Default)]
pub struct Catalogue {
    bundled: BTreeSet<String>,
}

impl Catalogue {
    pub fn new(bundled: Vec<String>) -> Self {
        Self { bundled: bundled.into_iter().collect() }
    }

    /// Whether `id` (of a checked form) is a bundled material.
    pub fn is_bundled(&self, id: &str) -> bool {
        self.bundled.contains(id)
    }

    /// The bundled ids, sorted.
    pub fn bundled(&self) -> impl Iterator<Item = &String> {
        self.bundled.iter()
    }

    /// Checks `id`: its form, and that it is bundled or an upload (uploads are looked up by the
    /// editor, which holds them).
    pub fn check(&self, id: &str) -> Checked<()> {
        check_id(id)?;
        if self.is_bundled(id) || id.starts_with(&format!("{UPLOAD_COLLECTION}/")) {
            return Ok(());
        }
        Err(Refusal::NotFound(format!(
            "unknown material {id:?} (GET /api/materials lists the bundled ones)"
        )))
    }
}

/// The preview scene the page picks: a shape under the sun and sky.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SceneChoice {
    /// sphere, plane, torus, ellipsoid or cylinder.
    pub shape: String,
    /// Sun elevation above the horizon, degrees, in (0, 90].
    pub sun_elevation: f64,
    /// Sun azimuth, degrees from the camera's side, in [-180, 180].
    pub sun_azimuth: f64,
    /// Preetham turbidity, in [2, 10].
    pub turbidity: f64,
}

impl Default for SceneChoice {
    /// The preview scene of the rest of the project (`SceneConfig::default()`: sphere, sun
    /// 40 degrees high, 30 degrees to the side, turbidity 3).
    fn default() -> Self {
        Self { shape: "sphere".into(), sun_elevation: 40.0, sun_azimuth: 30.0, turbidity: 3.0 }
    }
}

impl SceneChoice {
    /// The scene, checked.
    pub fn config(&self) -> Checked<SceneConfig> {
        let shape: Shape = self.shape.parse().map_err(|e| bad(format!("{e}")))?;
        let in_range = |v: f64, lo: f64, hi: f64| v.is_finite() && v >= lo && v <= hi;
        if !(in_range(self.sun_elevation, 0.0, 90.0) && self.sun_elevation > 0.0) {
            return Err(bad(format!(
                "sun elevation {} must be in (0, 90] degrees",
                self.sun_elevation
            )));
        }
        if !in_range(self.sun_azimuth, -180.0, 180.0) {
            return Err(bad(format!(
                "sun azimuth {} must be in [-180, 180] degrees",
                self.sun_azimuth
            )));
        }
        if !in_range(self.turbidity, 2.0, 10.0) {
            return Err(bad(format!("turbidity {} must be in [2, 10]", self.turbidity)));
        }
        let light = LightSpec::Sun {
            elevation_deg: self.sun_elevation,
            azimuth_deg: self.sun_azimuth,
            turbidity: self.turbidity,
        };
        Ok(SceneConfig {
            shape,
            light,
            projection: Projection::Orthographic,
            ..SceneConfig::default()
        })
    }
}

/// A second material blended with the first: `(1 - t) z_a + t z_b` in the latent space for the
/// latent modes, `(1 - t) A + t B` of the tables for the others.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlendRequest {
    pub material: String,
    pub t: f64,
}

/// The edit the page shows: a material (optionally blended with a second one), the attributes
/// it sets (each absent one left as the material's) and the scene of the preview.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EditRequest {
    pub material: String,
    #[serde(default)]
    pub blend: Option<BlendRequest>,
    #[serde(default)]
    pub diffuse: Option<[f64; 3]>,
    #[serde(default)]
    pub specular: Option<[f64; 3]>,
    #[serde(default)]
    pub roughness: Option<f64>,
    /// `paper` or `residual` (default: the project's default edit, residual).
    #[serde(default)]
    pub mode: Option<String>,
    #[serde(default)]
    pub scene: SceneChoice,
}

/// An [`EditRequest`] checked: ids of a valid form and known, the blend weight in range, the
/// mode and scene parsed. The attribute values are checked against the material's by
/// [`Edit::apply`] when the edit is made.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedEdit {
    pub material: String,
    pub blend: Option<(String, f64)>,
    pub edit: Edit,
    pub mode: EditMode,
    pub scene: SceneConfig,
}

impl EditRequest {
    /// Checks the request against `catalogue`.
    pub fn check(&self, catalogue: &Catalogue) -> Checked<CheckedEdit> {
        catalogue.check(&self.material)?;
        let blend = match &self.blend {
            None => None,
            Some(b) => {
                catalogue.check(&b.material)?;
                if !(b.t.is_finite() && (0.0..=1.0).contains(&b.t)) {
                    return Err(bad(format!("blend weight {} must be in [0, 1]", b.t)));
                }
                Some((b.material.clone(), b.t))
            }
        };
        let mode = match self.mode.as_deref() {
            None => DEFAULT_LATENT_MODE,
            Some(name) => name.parse::<EditMode>().map_err(|e| bad(e.to_string()))?,
        };
        let edit = Edit {
            diffuse: self.diffuse.map(ColourEdit::Set),
            specular: self.specular.map(ColourEdit::Set),
            roughness: self.roughness.map(ScalarEdit::Set),
        };
        Ok(CheckedEdit {
            material: self.material.clone(),
            blend,
            edit,
            mode,
            scene: self.scene.config()?,
        })
    }
}

/// How good a preview: the fast first pass while a slider moves, or the refined one after.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Quality {
    Fast,
    Refined,
}

/// A preview request: the edit, the quality, and the page's own sequence number (echoed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PreviewRequest {
    pub edit: EditRequest,
    pub quality: Quality,
    #[serde(default)]
    pub sequence: u64,
}

/// The 7 attributes as JSON.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AttributesJson {
    pub diffuse: [f64; 3],
    pub specular: [f64; 3],
    pub roughness: f64,
}

impl From<&deepbrdf_eval::attributes::Attributes> for AttributesJson {
    fn from(a: &deepbrdf_eval::attributes::Attributes) -> Self {
        Self { diffuse: a.diffuse, specular: a.specular, roughness: a.roughness }
    }
}

/// Checks the file name of an upload and returns the material's name (the stem) and whether it
/// is an RGL `.bsdf` file (else a MERL `.binary`).
pub fn check_upload_name(file_name: &str) -> Checked<(String, bool)> {
    let (stem, bsdf) = match (file_name.strip_suffix(".binary"), file_name.strip_suffix(".bsdf")) {
        (Some(stem), _) => (stem, false),
        (_, Some(stem)) => (stem, true),
        _ => return Err(bad(format!("upload {file_name:?}: expected a .binary or .bsdf file"))),
    };
    let ok = |c: char| c.is_ascii_alphanumeric() || "-_.+ ()".contains(c);
    if stem.is_empty() || stem.len() > 80 || !stem.chars().all(ok) || stem.contains("..") {
        return Err(bad(format!(
            "upload {file_name:?}: the file name must be letters, digits and -_.+() (no path)"
        )));
    }
    Ok((stem.to_string(), bsdf))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn catalogue() -> Catalogue {
        Catalogue::new(vec!["merl/chrome".into(), "rgl-measured/paper_white_rgb".into()])
    }

    #[test]
    fn mutated_requests_are_checked_or_refused_never_a_panic() {
        use deepbrdf_data::testing::mutate::{fuzz, inputs, Focus};
        let c = catalogue();
        let preview = br#"{"edit":{"material":"merl/chrome","blend":{"material":"rgl-measured/paper_white_rgb","t":0.25},"diffuse":[0.2,0.1,0.05],"specular":[0.04,0.04,0.04],"roughness":0.1,"mode":"paper","scene":{"shape":"torus","sun_elevation":35.0,"sun_azimuth":-20.0,"turbidity":4.0}},"quality":"fast","sequence":7}"#;
        let plain = br#"{"edit":{"material":"merl/chrome"},"quality":"refined"}"#;
        let corpus = vec![preview.to_vec(), plain.to_vec(), b"red-plastic (2).binary".to_vec()];
        for seed in &corpus[..2] {
            let r: PreviewRequest = serde_json::from_slice(seed).unwrap();
            r.edit.check(&c).unwrap();
        }
        let n = inputs(20_000);
        let report = fuzz(&corpus, 2028, n, Focus { header: 48, header_share: 0.3 }, |b| {
            let _ = check_upload_name(&String::from_utf8_lossy(b));
            let request: PreviewRequest =
                serde_json::from_slice(b).map_err(|e| bad(e.to_string()))?;
            let checked = request.edit.check(&c)?;
            // What passes the check is what the editor may use.
            assert!(c.is_bundled(&checked.material), "{}", checked.material);
            if let Some((m, t)) = &checked.blend {
                assert!(c.is_bundled(m) && (0.0..=1.0).contains(t), "{m} {t}");
            }
            Ok::<_, Refusal>(checked)
        });
        eprintln!("editor requests: {report:?}");
        assert!(report.panics.is_empty(), "panics: {:?}", report.panics);
        assert!(report.accepted > 0 && report.rejected > 0, "{report:?}");
    }

    #[test]
    fn ids_are_names_never_paths() {
        let c = catalogue();
        assert!(c.check("merl/chrome").is_ok());
        assert!(c.check("upload/0123abcd").is_ok());
        assert!(matches!(c.check("merl/gold"), Err(Refusal::NotFound(_))));
        for id in [
            "../etc/passwd",
            "/etc/passwd",
            "merl/../x",
            "a/b/c",
            "merl\\chrome",
            "chrome",
            "",
            "merl/ch rome",
        ] {
            assert!(matches!(c.check(id), Err(Refusal::BadRequest(_))), "{id}");
        }
    }

    #[test]
    fn edits_and_scenes_are_checked() {
        let c = catalogue();
        let mut r = EditRequest {
            material: "merl/chrome".into(),
            blend: Some(BlendRequest { material: "rgl-measured/paper_white_rgb".into(), t: 0.5 }),
            diffuse: Some([0.1, 0.2, 0.3]),
            specular: None,
            roughness: Some(0.1),
            mode: None,
            scene: SceneChoice::default(),
        };
        let e = r.check(&c).unwrap();
        assert_eq!(e.mode, DEFAULT_LATENT_MODE);
        assert_eq!(e.scene, SceneConfig::default());
        assert_eq!(e.edit.diffuse, Some(ColourEdit::Set([0.1, 0.2, 0.3])));
        r.blend.as_mut().unwrap().t = 1.5;
        assert!(r.check(&c).unwrap_err().message().contains("blend weight"));
        r.blend = None;
        r.mode = Some("linear".into());
        assert!(r.check(&c).unwrap_err().message().contains("mode"));
        r.mode = Some("stretch".into());
        assert_eq!(r.check(&c).unwrap().mode, EditMode::Stretch);
        r.mode = None;
        for (scene, needle) in [
            (SceneChoice { shape: "cube".into(), ..SceneChoice::default() }, "shape"),
            (SceneChoice { sun_elevation: 0.0, ..SceneChoice::default() }, "elevation"),
            (SceneChoice { sun_azimuth: f64::NAN, ..SceneChoice::default() }, "azimuth"),
            (SceneChoice { turbidity: 50.0, ..SceneChoice::default() }, "turbidity"),
        ] {
            r.scene = scene;
            assert!(r.check(&c).unwrap_err().message().contains(needle), "{needle}");
        }
    }

    #[test]
    fn upload_names_have_no_path() {
        assert_eq!(check_upload_name("gold.binary").unwrap(), ("gold".into(), false));
        assert_eq!(check_upload_name("paper (1).bsdf").unwrap(), ("paper (1)".into(), true));
        for name in ["../x.binary", "a/b.binary", "x.exe", ".binary", "a\\b.bsdf"] {
            assert!(check_upload_name(name).is_err(), "{name}");
        }
    }
}
