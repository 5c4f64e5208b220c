//! The work the HTTP handlers hand the editor's worker thread: jobs answered in order, and one
//! latest-wins preview slot with a generation counter (see [`super::editor`]).
use super::replies::{Download, DownloadFile, Failure, MaterialInfo, Preview};
use super::request::{CheckedEdit, Quality};
use deepbrdf_render::SceneConfig;
use std::collections::VecDeque;
use std::sync::atomic::AtomicU64;
use std::sync::{Condvar, Mutex};
use tokio::sync::oneshot;

/// Where the worker sends a job's result.
pub(super) type Reply<T> = oneshot::Sender<Result<T, Failure>>;

/// A job answered in arrival order.
pub(super) enum Job {
    Open { id: String, reply: Reply<MaterialInfo> },
    Upload { file_name: String, bytes: Vec<u8>, reply: Reply<MaterialInfo> },
    Original { id: String, scene: SceneConfig, reply: Reply<Vec<u8>> },
    Download { edit: CheckedEdit, what: Download, reply: Reply<DownloadFile> },
}

/// A preview job: latest wins (see [`Queue`]).
pub(super) struct PreviewJob {
    pub edit: CheckedEdit,
    pub quality: Quality,
    /// Its number among the previews submitted; a running preview stops once a newer exists.
    pub generation: u64,
    pub reply: Reply<Preview>,
}

/// The waiting work: jobs in order and one preview slot (a new preview replaces a waiting
/// one).
#[derive(Default)]
pub(super) struct Queue {
    pub jobs: VecDeque<Job>,
    pub preview: Option<PreviewJob>,
}

/// What the handlers and the worker share: the queue, the worker's wake-up, the newest
/// preview's generation.
pub(super) struct Shared {
    pub queue: Mutex<Queue>,
    pub wake: Condvar,
    /// Generation of the newest preview submitted.
    pub latest: AtomicU64,
}
