//! `experiments serve [--model DIR] [--host ADDR] [--port N]`: the browser material editor
//! (§5.1's edits, interactively): pick or drop a material, move the 7 attribute sliders and a blend slider, see
//! the original and the edited material side by side, download the edited `.binary` and its
//! latent. Binds 127.0.0.1 unless told otherwise; see [`crate::serve`].
use crate::args::data::CacheArg;
use crate::editing::EditorArg;
use crate::serve::launch::{runtime, start};
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
