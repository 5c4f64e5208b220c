//! Starting the browser editor's server: its runtime, and the editor (model and regressor
//! loaded) bound to an address; shared by `serve` and `bench serve`.
use super::editor::EditorHandle;
use super::request::{bundled_ids, Catalogue};
use crate::args::data::CacheArg;
use crate::editing::EditorArg;
use anyhow::Context;
use std::net::SocketAddr;

/// Starts the editor (model and regressor loaded) and binds `addr`: the listener and the
/// handle.
pub fn start(
    runtime: &tokio::runtime::Runtime,
    editor: &EditorArg,
    cache: &CacheArg,
    addr: SocketAddr,
) -> anyhow::Result<(tokio::net::TcpListener, EditorHandle)> {
    let model_dir = editor.model.dir()?;
    let catalogue = Catalogue::new(bundled_ids()?);
    let editor =
        EditorHandle::start(&model_dir, editor.regressor.as_deref(), cache.cache(), catalogue)?;
    let listener = runtime
        .block_on(tokio::net::TcpListener::bind(addr))
        .with_context(|| format!("listening on {addr}"))?;
    Ok((listener, editor))
}

/// The runtime of the server: two worker threads answer HTTP while the editor thread and
/// rayon render.
pub fn runtime() -> anyhow::Result<tokio::runtime::Runtime> {
    Ok(tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?)
}
