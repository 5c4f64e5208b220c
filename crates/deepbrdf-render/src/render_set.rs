//! The synthetic training set of single-image recovery (Hu et al. 2020, §5.2: "10000 synthetic
//! images ... Each image only contains one virtual object", rendered under sun and sky) on
//! disk: a folder of images `img-NNNNNN.png` (optionally `.exr`, linear with coverage) and
//! `manifest.json`, which lists every image's material, scene and seed.
//!
//! Image `i` shows material `i mod n` of the set's `n` materials in the scene
//! [`SceneSampler::sample`] draws for `i`: the manifest follows from its header alone, so a
//! killed run resumes by rendering the images whose files are missing (each file is written
//! atomically, so one that exists is complete), and a larger `--images` extends a set without
//! touching what is there.

use crate::brdf::MerlBrdf;
use crate::error::{RenderError, Result};
use crate::integrator::{render, RenderSettings};
use crate::sampler::Sampler;
use crate::scene_sampler::{camera_png, SampledScene, SceneSampler};
use deepbrdf_data::{MerlTable, Progress, Silent};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// File name of the manifest.
pub const SET_MANIFEST: &str = "manifest.json";
const FORMAT: &str = "deepbrdf-render-set";
const VERSION: u32 = 1;
/// Largest manifest read (a million images).
const MAX_MANIFEST_BYTES: u64 = 1 << 30;

/// What a set is made of: everything its images follow from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SetHeader {
    /// Where the materials come from (a collection's name or a folder).
    pub data: String,
    /// The materials, as `deepbrdf_data::dataset::load_material` names them (`merl/chrome`, a
    /// file path), in the order images cycle through them.
    pub materials: Vec<String>,
    /// Materials of the data left out (a held-out fold), for the record.
    pub excluded: Vec<String>,
    pub seed: u64,
    /// Image side in pixels and samples per pixel.
    pub size: u32,
    pub spp: u32,
    /// Whether each image also has a linear EXR.
    pub exr: bool,
    pub sampler: SceneSampler,
    /// The renderer's random numbers (sets made before there was a choice: independent).
    #[serde(default = "Sampler::stored_default")]
    pub pixel_sampler: Sampler,
}

/// One image of the set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SetImage {
    pub index: usize,
    /// PNG file name inside the set's folder.
    pub file: String,
    pub material: String,
    pub scene: SampledScene,
}

/// The manifest: header and every image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderSet {
    format: String,
    version: u32,
    pub header: SetHeader,
    pub images: Vec<SetImage>,
}

impl RenderSet {
    /// The set of `count` images of `header`.
    pub fn plan(header: SetHeader, count: usize) -> Result<Self> {
        header.sampler.validate()?;
        RenderSettings {
            size: header.size,
            spp: header.spp,
            seed: 0,
            jitter: true,
            sampler: header.pixel_sampler,
        }
        .validate()?;
        if header.materials.is_empty() || count == 0 {
            return Err(RenderError::Invalid(
                "a render set needs at least one material and one image".into(),
            ));
        }
        let images = (0..count)
            .map(|index| SetImage {
                index,
                file: format!("img-{index:06}.png"),
                material: header.materials[index % header.materials.len()].clone(),
                scene: header.sampler.sample(header.seed, index as u64),
            })
            .collect();
        Ok(Self { format: FORMAT.into(), version: VERSION, header, images })
    }

    /// Reads the manifest of the set in `dir`.
    pub fn load(dir: &Path) -> Result<Self> {
        let path = dir.join(SET_MANIFEST);
        let meta = std::fs::metadata(&path).map_err(|e| {
            RenderError::format(&path, format!("not a render set (no readable manifest): {e}"))
        })?;
        if meta.len() > MAX_MANIFEST_BYTES {
            return Err(RenderError::format(&path, "too large for a render set manifest"));
        }
        let text = std::fs::read(&path).map_err(|e| RenderError::format(&path, e.to_string()))?;
        let set: Self = serde_json::from_slice(&text)
            .map_err(|e| RenderError::format(&path, format!("not a render set manifest: {e}")))?;
        if set.format != FORMAT || set.version != VERSION {
            return Err(RenderError::format(
                &path,
                format!(
                    "format {} version {}, expected {FORMAT} {VERSION}",
                    set.format, set.version
                ),
            ));
        }
        // Its images must be what its header plans (an edited manifest is refused).
        let planned = Self::plan(set.header.clone(), set.images.len())
            .map_err(|e| RenderError::format(&path, e.to_string()))?;
        if planned.images != set.images {
            return Err(RenderError::format(
                &path,
                "the images listed are not those the header describes (edited or damaged)",
            ));
        }
        Ok(set)
    }

    /// Writes the manifest into `dir` atomically.
    pub fn save(&self, dir: &Path) -> Result<()> {
        let json = serde_json::to_string(self)
            .map_err(|e| RenderError::Invalid(format!("cannot serialise the manifest: {e}")))?;
        Ok(deepbrdf_data::files::write_atomic(&dir.join(SET_MANIFEST), json.as_bytes())?)
    }

    /// Paths of image `i`'s PNG and EXR in `dir`.
    pub fn paths(&self, dir: &Path, i: usize) -> (PathBuf, PathBuf) {
        let png = dir.join(&self.images[i].file);
        (png.clone(), png.with_extension("exr"))
    }

    /// Whether every file of image `i` is in `dir`.
    pub fn is_complete(&self, dir: &Path, i: usize) -> bool {
        let (png, exr) = self.paths(dir, i);
        png.is_file() && (!self.header.exr || exr.is_file())
    }

    /// A digest of the manifest (what a network trained on the set records).
    pub fn digest(&self) -> String {
        use sha2::{Digest, Sha256};
        let json = serde_json::to_string(self).unwrap_or_default();
        hex::encode(&Sha256::digest(json.as_bytes())[..16])
    }

    /// Renders every image of the set missing from `dir`, material by material (`load` gives a
    /// material's table), the images of one material in parallel; returns how many were
    /// rendered. Progress counts images, those already there included.
    pub fn render_missing(
        &self,
        dir: &Path,
        load: &(dyn Fn(&str) -> std::result::Result<MerlTable, String> + Sync),
        progress: &dyn Progress,
    ) -> Result<usize> {
        let n = self.header.materials.len();
        progress.start(self.images.len() as u64, "rendering the set");
        let done = (0..self.images.len()).filter(|&i| self.is_complete(dir, i)).count();
        progress.advance(done as u64);
        let mut rendered = 0;
        for (m, material) in self.header.materials.iter().enumerate() {
            let todo: Vec<usize> =
                (m..self.images.len()).step_by(n).filter(|&i| !self.is_complete(dir, i)).collect();
            if todo.is_empty() {
                continue;
            }
            let table = load(material)
                .map_err(|e| RenderError::Invalid(format!("loading material {material}: {e}")))?;
            let brdf = MerlBrdf::new(&table);
            todo.par_iter().try_for_each(|&i| {
                self.render_one(dir, i, &brdf)?;
                progress.advance(1);
                Ok::<(), RenderError>(())
            })?;
            rendered += todo.len();
        }
        progress.finish();
        Ok(rendered)
    }

    fn render_one(&self, dir: &Path, i: usize, brdf: &MerlBrdf) -> Result<()> {
        let image = &self.images[i];
        let s = &image.scene;
        let scene = s.scene.build()?;
        let settings = RenderSettings {
            size: self.header.size,
            spp: self.header.spp,
            seed: s.render_seed,
            jitter: true,
            sampler: self.header.pixel_sampler,
        };
        let linear = render(&scene, brdf, &settings, &Silent)?;
        let (png, exr) = self.paths(dir, i);
        if self.header.exr {
            linear.write_exr(&exr)?;
        }
        camera_png(&linear, s.exposure, s.noise, s.render_seed).write_png(&png)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::testing::synthetic_table;

    fn header() -> SetHeader {
        SetHeader {
            data: "synthetic".into(),
            materials: vec!["a".into(), "b".into()],
            excluded: vec![],
            seed: 3,
            size: 12,
            spp: 2,
            exr: true,
            sampler: SceneSampler::default(),
            pixel_sampler: Sampler::Sobol,
        }
    }

    fn load(name: &str) -> std::result::Result<MerlTable, String> {
        match name {
            "a" => Ok(synthetic_table(0)),
            "b" => Ok(synthetic_table(4)),
            _ => Err(format!("no material {name}")),
        }
    }

    #[test]
    fn a_set_renders_resumes_and_extends_without_redoing_images() {
        let dir = tempfile::tempdir().unwrap();
        let set = RenderSet::plan(header(), 4).unwrap();
        set.save(dir.path()).unwrap();
        assert_eq!(RenderSet::load(dir.path()).unwrap(), set);
        assert_eq!(set.images[3].material, "b");
        assert_eq!(set.render_missing(dir.path(), &load, &Silent).unwrap(), 4);
        let first = std::fs::read(dir.path().join("img-000002.png")).unwrap();
        // A lost image is rendered again, bit for bit; the others are left alone.
        std::fs::remove_file(dir.path().join("img-000002.png")).unwrap();
        let kept =
            std::fs::metadata(dir.path().join("img-000001.png")).unwrap().modified().unwrap();
        assert_eq!(set.render_missing(dir.path(), &load, &Silent).unwrap(), 1);
        assert_eq!(std::fs::read(dir.path().join("img-000002.png")).unwrap(), first);
        let after =
            std::fs::metadata(dir.path().join("img-000001.png")).unwrap().modified().unwrap();
        assert_eq!(kept, after);
        assert!(dir.path().join("img-000002.exr").is_file());
        // More images: the first four are the same plan.
        let more = RenderSet::plan(header(), 6).unwrap();
        assert_eq!(more.images[..4], set.images[..]);
        assert_eq!(more.render_missing(dir.path(), &load, &Silent).unwrap(), 2);
        // An edited manifest is refused.
        let text = std::fs::read_to_string(dir.path().join(SET_MANIFEST)).unwrap();
        std::fs::write(dir.path().join(SET_MANIFEST), text.replace("img-000003", "img-000009"))
            .unwrap();
        let e = RenderSet::load(dir.path()).unwrap_err().to_string();
        assert!(e.contains("manifest.json") && e.contains("edited"), "{e}");
        // A material that cannot be loaded is named.
        let mut bad = header();
        bad.materials.push("zz".into());
        let other = tempfile::tempdir().unwrap();
        let e = RenderSet::plan(bad, 3).unwrap().render_missing(other.path(), &load, &Silent);
        assert!(e.unwrap_err().to_string().contains("zz"));
    }
}
