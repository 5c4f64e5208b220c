//! `experiments serve [--model DIR] [--host ADDR] [--port N]`: the browser material editor
//! (§5.1's edits, interactively): pick or drop a material, move the 7 attribute sliders and a blend slider, see
//! the original and the edited material side by side, download the edited `.binary` and its
//! latent. Binds 127.0.0.1 unless told otherwise; see [`crate::serve`].
use crate::args::data::CacheArg;
use crate::editing::EditorArg;
use crate::serve::editor::EditorHandle;
use crate::serve::request::{bundled_ids, Catalogue};
use anyhow::Context;
use deepbrdf_data::Progress;
use std::io::Write;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub editor: EditorArg,
    /// Address to listen on (another than loopback lets other machines edit with this one).
    #[arg(long, value_name = "ADDR", default_value_t = IpAddr::V4(Ipv4Addr::LOCALHOST))]
    pub host: IpAddr,
    /// Port to listen on (0: any free port; the address is printed).
    #[arg(long, default_value_t = 7878)]
    pub port: u16,
    #[command(flatten)]
    pub cache: CacheArg,
}

/// Starts the editor (model and regressor loaded) and binds `addr`: the listener and the
/// handle, shared by `serve` and `bench serve`.
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

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    let runtime = runtime()?;
    let addr = SocketAddr::new(args.host, args.port);
    let (listener, editor) = start(&runtime, &args.editor, &args.cache, addr)?;
    let local = listener.local_addr()?;
    println!(
        "editing with model {} (k = {}) from {}",
        editor.model.model_id, editor.model.k, editor.model.model_dir
    );
    println!("serving the editor at http://{local}/ (Ctrl-C stops it)");
    std::io::stdout().flush()?;
    runtime.block_on(async move { axum::serve(listener, crate::serve::router(editor)).await })?;
    Ok(())
}
