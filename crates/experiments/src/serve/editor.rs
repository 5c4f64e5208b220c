//! The editor behind `experiments serve`: one worker thread owns the DeepBRDF model and its
//! regressor (loaded there, so neither needs to be shared between threads) and the caches of
//! what the page asks for again and again (opened materials with their attribute fit, latent
//! and table sampler; decoded tables per latent; built scenes; renders of the originals). The
//! HTTP handlers hand it jobs through [`EditorHandle`] and await the reply.
//!
//! Previews are latest-wins: there is one preview slot, a new preview replaces a waiting one
//! (which is answered [`Failure::Superseded`]), and a running preview stops between its stages
//! (decode, each render pass) once a newer one has arrived (a generation counter). So a dragged
//! slider never queues up work: at most the stage under way finishes first. The fast preview
//! renders the edited table at [`FAST`] with the original material's table sampler, built once
//! when the material is opened; the refined one builds the edited table's own sampler and
//! renders [`REFINED`] in passes.
use super::request::{
    check_upload_name, Catalogue, CheckedEdit, Quality, Refusal, UPLOAD_COLLECTION,
};
use crate::editing;
use crate::latent_file::LatentFile;
use deepbrdf_data::cache::Cache;
use deepbrdf_data::dataset::load_bundled_material;
use deepbrdf_data::merl::{merl_bytes, MerlFile};
use deepbrdf_data::{MerlTable, Silent};
use deepbrdf_eval::attributes::{Attributes, FitConfig};
use deepbrdf_eval::editing::parts::{fit_parts, Parts, PartsConfig};
use deepbrdf_model::regressor::Regressor;
use deepbrdf_model::DeepBrdf;
use deepbrdf_render::{
    render, Image, MerlBrdf, MerlSampling, RenderSettings, Sampler, Scene, SceneConfig, Tonemap,
};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock};
use std::time::Instant;
use tokio::sync::oneshot;

mod plan;

use super::queue::{Job, PreviewJob, Queue, Reply, Shared};
use super::recent::Recent;
use super::replies::internal;
pub use super::replies::{
    Download, DownloadFile, Failure, MaterialInfo, ModelInfo, Preview, Seconds,
};

/// The fast preview: 128 px, 4 samples per pixel.
pub const FAST: RenderSettings =
    RenderSettings { size: 128, spp: 4, seed: PREVIEW_SEED, jitter: true, sampler: Sampler::Sobol };
/// The refined preview (and the originals): 256 px, 32 samples per pixel, in
/// [`REFINED_PASSES`] passes of different seeds.
pub const REFINED: RenderSettings = RenderSettings {
    size: 256,
    spp: 32,
    seed: PREVIEW_SEED,
    jitter: true,
    sampler: Sampler::Sobol,
};
/// Passes of the refined preview (a newer request stops it between two).
pub const REFINED_PASSES: u32 = 8;
/// Seed of the previews: the same for every edit, so two previews differ by the edit only.
const PREVIEW_SEED: u64 = 0x5eed;
/// Materials kept open (each ~40 MB: its table, the interleaved copy, its sampler).
const OPEN_MATERIALS: usize = 8;
/// Decoded tables kept (17.5 MB each), by latent; as many edited tables of the modes that
/// edit the table itself, by edit ([`plan`]).
const DECODED_TABLES: usize = 4;
/// Renders of originals kept (PNG bytes), by material and scene.
const ORIGINAL_RENDERS: usize = 32;
/// Background of the previews (8-bit sRGB), behind the shape.
const BACKGROUND: [u8; 3] = [40, 40, 44];

/// The handlers' side of the editor: submit jobs, await replies. Cheap to clone.
#[derive(Clone)]
pub struct EditorHandle {
    shared: Arc<Shared>,
    pub catalogue: Arc<Catalogue>,
    pub model: Arc<ModelInfo>,
}

impl EditorHandle {
    /// Starts the worker: loads the model of `model_dir` and its regressor (`regressor`, else
    /// `<model>/regressor`) on the worker thread and returns once they are loaded.
    pub fn start(
        model_dir: &Path,
        regressor: Option<&Path>,
        cache: Cache,
        catalogue: Catalogue,
    ) -> anyhow::Result<Self> {
        let shared = Arc::new(Shared {
            queue: Mutex::new(Queue::default()),
            wake: Condvar::new(),
            latest: AtomicU64::new(0),
        });
        let catalogue = Arc::new(catalogue);
        let (ready_tx, ready_rx) = std::sync::mpsc::channel();
        let (dir, regressor) = (model_dir.to_path_buf(), regressor.map(Path::to_path_buf));
        let (worker_shared, worker_catalogue) = (shared.clone(), catalogue.clone());
        std::thread::Builder::new().name("editor".into()).spawn(move || {
            let loaded = (|| {
                let device = crate::args::device::device()?;
                editing::load_editor(&dir, regressor.as_deref(), &device)
            })();
            match loaded {
                Err(e) => {
                    let _ = ready_tx.send(Err(e));
                }
                Ok((model, regressor)) => {
                    let info = ModelInfo {
                        model_id: model.id().to_string(),
                        k: model.k(),
                        model_dir: dir.canonicalize().unwrap_or(dir).display().to_string(),
                    };
                    let _ = ready_tx.send(Ok(info));
                    Editor::new(model, regressor, cache, worker_catalogue, worker_shared).run();
                }
            }
        })?;
        let model = ready_rx.recv().map_err(|_| anyhow::anyhow!("the editor thread stopped"))??;
        Ok(Self { shared, catalogue, model: Arc::new(model) })
    }

    fn submit<T>(
        &self,
        job: impl FnOnce(Reply<T>) -> Job,
    ) -> oneshot::Receiver<Result<T, Failure>> {
        let (tx, rx) = oneshot::channel();
        let mut q = self.shared.queue.lock().unwrap_or_else(|p| p.into_inner());
        q.jobs.push_back(job(tx));
        drop(q);
        self.shared.wake.notify_one();
        rx
    }

    async fn wait<T>(rx: oneshot::Receiver<Result<T, Failure>>) -> Result<T, Failure> {
        rx.await.unwrap_or_else(|_| Err(Failure::Internal("the editor thread stopped".into())))
    }

    /// Opens a bundled material (or finds an upload): its attributes and latent.
    pub async fn open(&self, id: String) -> Result<MaterialInfo, Failure> {
        Self::wait(self.submit(|reply| Job::Open { id, reply })).await
    }

    /// Reads an uploaded `.binary` or `.bsdf` file (kept in memory; a `.bsdf` is converted
    /// through the server's cache) and opens it.
    pub async fn upload(&self, file_name: String, bytes: Vec<u8>) -> Result<MaterialInfo, Failure> {
        Self::wait(self.submit(|reply| Job::Upload { file_name, bytes, reply })).await
    }

    /// The PNG of an original material's render.
    pub async fn original(&self, id: String, scene: SceneConfig) -> Result<Vec<u8>, Failure> {
        Self::wait(self.submit(|reply| Job::Original { id, scene, reply })).await
    }

    /// The edited table or latent as a file.
    pub async fn download(
        &self,
        edit: CheckedEdit,
        what: Download,
    ) -> Result<DownloadFile, Failure> {
        Self::wait(self.submit(|reply| Job::Download { edit, what, reply })).await
    }

    /// A preview of `edit`; replaces (and supersedes) a preview still waiting.
    pub async fn preview(&self, edit: CheckedEdit, quality: Quality) -> Result<Preview, Failure> {
        let (tx, rx) = oneshot::channel();
        let generation = self.shared.latest.fetch_add(1, Ordering::SeqCst) + 1;
        let job = PreviewJob { edit, quality, generation, reply: tx };
        let replaced = {
            let mut q = self.shared.queue.lock().unwrap_or_else(|p| p.into_inner());
            q.preview.replace(job)
        };
        self.shared.wake.notify_one();
        if let Some(old) = replaced {
            let _ = old.reply.send(Err(Failure::Superseded));
        }
        Self::wait(rx).await
    }
}

/// An opened material.
struct Material {
    id: String,
    name: String,
    table: MerlTable,
    attributes: Attributes,
    latent: Vec<f32>,
    /// The table sampler built from its values (shared by the fast previews of its edits).
    sampling: MerlSampling,
    /// Its parts, fitted on its first parts edit and kept for the next.
    parts: OnceLock<Parts>,
}

impl Material {
    /// The table's parts ([`deepbrdf_eval::editing::parts`]).
    fn parts(&self) -> Result<&Parts, Failure> {
        if let Some(p) = self.parts.get() {
            return Ok(p);
        }
        let fitted = fit_parts(&self.table, &PartsConfig::default())?.parts;
        Ok(self.parts.get_or_init(|| fitted))
    }

    fn info(&self) -> MaterialInfo {
        MaterialInfo {
            id: self.id.clone(),
            name: self.name.clone(),
            attributes: (&self.attributes).into(),
            latent: self.latent.clone(),
        }
    }
}

/// The worker's state.
struct Editor {
    model: DeepBrdf,
    regressor: Regressor,
    cache: Cache,
    catalogue: Arc<Catalogue>,
    shared: Arc<Shared>,
    materials: Recent<String, Arc<Material>>,
    decoded: Recent<Vec<u32>, Arc<MerlTable>>,
    edited: Recent<String, Arc<MerlTable>>,
    scenes: Recent<String, Arc<Scene>>,
    originals: Recent<String, Arc<Vec<u8>>>,
}

enum Work {
    Job(Job),
    Preview(PreviewJob),
}

impl Editor {
    fn new(
        model: DeepBrdf,
        regressor: Regressor,
        cache: Cache,
        catalogue: Arc<Catalogue>,
        shared: Arc<Shared>,
    ) -> Self {
        Self {
            model,
            regressor,
            cache,
            catalogue,
            shared,
            materials: Recent::new(OPEN_MATERIALS),
            decoded: Recent::new(DECODED_TABLES),
            edited: Recent::new(DECODED_TABLES),
            scenes: Recent::new(8),
            originals: Recent::new(ORIGINAL_RENDERS),
        }
    }

    /// Serves jobs until the process ends: other jobs first, then the one waiting preview.
    fn run(mut self) {
        loop {
            let work = {
                let mut q = self.shared.queue.lock().unwrap_or_else(|p| p.into_inner());
                loop {
                    if let Some(job) = q.jobs.pop_front() {
                        break Work::Job(job);
                    }
                    if let Some(p) = q.preview.take() {
                        break Work::Preview(p);
                    }
                    q = self.shared.wake.wait(q).unwrap_or_else(|p| p.into_inner());
                }
            };
            match work {
                Work::Job(Job::Open { id, reply }) => {
                    let _ = reply.send(self.material(&id).map(|m| m.info()));
                }
                Work::Job(Job::Upload { file_name, bytes, reply }) => {
                    let _ = reply.send(self.upload(&file_name, &bytes));
                }
                Work::Job(Job::Original { id, scene, reply }) => {
                    let _ = reply.send(self.original(&id, &scene).map(|p| p.to_vec()));
                }
                Work::Job(Job::Download { edit, what, reply }) => {
                    let _ = reply.send(self.download(&edit, what));
                }
                Work::Preview(job) => {
                    let result = self.preview(&job.edit, job.quality, job.generation);
                    let _ = job.reply.send(result);
                }
            }
        }
    }

    /// An opened material: from the list, else loaded (bundled ids only; uploads are only in
    /// the list).
    fn material(&mut self, id: &str) -> Result<Arc<Material>, Failure> {
        self.catalogue.check(id)?;
        if let Some(m) = self.materials.get(&id.to_string()) {
            return Ok(m);
        }
        if !self.catalogue.is_bundled(id) {
            return Err(Refusal::NotFound(format!(
                "material {id:?} is not open (an upload is kept while among the {OPEN_MATERIALS} \
                 most recent materials): drop the file again"
            ))
            .into());
        }
        let (name, table) = load_bundled_material(id, &self.cache).map_err(internal)?;
        self.open(id.to_string(), name, table)
    }

    /// Fits, encodes and builds the sampler of a table, and keeps it open.
    fn open(
        &mut self,
        id: String,
        name: String,
        table: MerlTable,
    ) -> Result<Arc<Material>, Failure> {
        let attributes = editing::attributes_of(&table, &name, &FitConfig::default())?;
        let latent = self.model.encode(&table).map_err(internal)?;
        let sampling = MerlBrdf::new(&table).sampling().clone();
        let parts = OnceLock::new();
        let m =
            Arc::new(Material { id: id.clone(), name, table, attributes, latent, sampling, parts });
        self.materials.put(id, m.clone());
        Ok(m)
    }

    fn upload(&mut self, file_name: &str, bytes: &[u8]) -> Result<MaterialInfo, Failure> {
        let (name, bsdf) = check_upload_name(file_name)?;
        let digest = hex::encode(&Sha256::digest(bytes)[..8]);
        let id = format!("{UPLOAD_COLLECTION}/{digest}");
        if let Some(m) = self.materials.get(&id) {
            return Ok(m.info());
        }
        let origin = PathBuf::from(format!("<upload {file_name}>"));
        let refused = |e: deepbrdf_data::DataError| Refusal::BadRequest(e.to_string());
        let table = match bsdf {
            true => self.cache.converted(&name, &origin, bytes).map_err(refused)?.0,
            false => {
                MerlFile::from_bytes(bytes, &origin).and_then(|f| f.to_table()).map_err(refused)?
            }
        };
        Ok(self.open(id, name, table)?.info())
    }

    fn scene(&mut self, config: &SceneConfig) -> Result<Arc<Scene>, Failure> {
        let key = format!("{config:?}");
        if let Some(s) = self.scenes.get(&key) {
            return Ok(s);
        }
        let scene = Arc::new(config.build().map_err(|e| Refusal::BadRequest(e.to_string()))?);
        self.scenes.put(key, scene.clone());
        Ok(scene)
    }

    /// The render of an original material (its own sampler, the refined settings), as PNG.
    fn original(&mut self, id: &str, config: &SceneConfig) -> Result<Arc<Vec<u8>>, Failure> {
        let key = format!("{id} {config:?}");
        if let Some(png) = self.originals.get(&key) {
            return Ok(png);
        }
        let m = self.material(id)?;
        let scene = self.scene(config)?;
        let brdf = MerlBrdf::new_sampled(&m.table, m.sampling.clone());
        let image = render(&scene, &brdf, &REFINED, &Silent).map_err(internal)?;
        let png = Arc::new(png(&image)?);
        self.originals.put(key, png.clone());
        Ok(png)
    }

    fn current(&self, generation: u64) -> Result<(), Failure> {
        match self.shared.latest.load(Ordering::SeqCst) == generation {
            true => Ok(()),
            false => Err(Failure::Superseded),
        }
    }

    fn preview(
        &mut self,
        edit: &CheckedEdit,
        quality: Quality,
        generation: u64,
    ) -> Result<Preview, Failure> {
        let t0 = Instant::now();
        let scene = self.scene(&edit.scene)?;
        // The regressor, then the decoder; a mode that edits the table counts as a decode.
        let plan = self.plan(edit)?;
        let t1 = Instant::now();
        self.current(generation)?;
        let table = self.table(edit, &plan)?;
        let t2 = Instant::now();
        self.current(generation)?;
        let (image, settings, achieved) = match quality {
            Quality::Fast => {
                let brdf = MerlBrdf::new_sampled(&table, plan.material.sampling.clone());
                (render(&scene, &brdf, &FAST, &Silent).map_err(internal)?, FAST, None)
            }
            Quality::Refined => {
                let brdf = MerlBrdf::new(&table);
                let pass = RenderSettings { spp: REFINED.spp / REFINED_PASSES, ..REFINED };
                let mut images = Vec::new();
                for p in 0..u64::from(REFINED_PASSES) {
                    self.current(generation)?;
                    let settings = RenderSettings { seed: REFINED.seed + p, ..pass };
                    images.push(render(&scene, &brdf, &settings, &Silent).map_err(internal)?);
                }
                self.current(generation)?;
                let achieved =
                    editing::attributes_of(&table, "the edited table", &FitConfig::quick())?;
                (Image::mean(&images).map_err(internal)?, REFINED, Some((&achieved).into()))
            }
        };
        let t3 = Instant::now();
        Ok(Preview {
            png: png(&image)?,
            quality,
            size: settings.size,
            spp: settings.spp,
            latent: plan.latent,
            requested: (&plan.requested).into(),
            base: (&plan.base).into(),
            achieved,
            seconds: Seconds {
                regressor: (t1 - t0).as_secs_f64(),
                decode: (t2 - t1).as_secs_f64(),
                render: (t3 - t2).as_secs_f64(),
                total: t0.elapsed().as_secs_f64(),
            },
        })
    }

    fn download(&mut self, edit: &CheckedEdit, what: Download) -> Result<DownloadFile, Failure> {
        let plan = self.plan(edit)?;
        let material = plan.material.clone();
        let stem: String = material
            .name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || "-_".contains(c) { c } else { '_' })
            .collect();
        Ok(match what {
            Download::Binary => DownloadFile {
                file_name: format!("{stem}-edited.binary"),
                bytes: merl_bytes(self.table(edit, &plan)?.as_ref()),
            },
            Download::Bsdf => {
                let file_name = format!("{stem}-edited.bsdf");
                let name = format!("{} (edited)", material.name);
                let resolution = deepbrdf_data::rgl::ExportResolution::default();
                let table = self.table(edit, &plan)?;
                let file = deepbrdf_data::rgl::export(&table, &name, &resolution, &file_name)
                    .map_err(internal)?;
                DownloadFile { file_name, bytes: file.to_bytes() }
            }
            Download::Latent => {
                let Some(z) = plan.latent else {
                    return Err(Refusal::BadRequest(format!(
                        "the {} edit edits the table, not the latent: download the .binary or \
                         .bsdf",
                        edit.mode
                    ))
                    .into());
                };
                DownloadFile {
                    file_name: format!("{stem}-edited.json"),
                    bytes: LatentFile::new(
                        self.model.id(),
                        &format!("{} (edited)", material.name),
                        z,
                    )
                    .to_bytes()?,
                }
            }
        })
    }
}

/// A preview image as PNG bytes (tonemapped, over the page's background).
fn png(image: &Image) -> Result<Vec<u8>, Failure> {
    image.to_srgb8(&Tonemap::default(), BACKGROUND).png_bytes().map_err(internal)
}
