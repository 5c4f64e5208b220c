//! A closed standard output ends the command quietly, as for any Unix tool
//! (`experiments tabulate ... | head -1`), instead of a panic in `println!`: the commands that
//! use no sockets get the default action of SIGPIPE back (Rust's runtime ignores it, so a write
//! to a closed pipe returns an error, and `println!` panics on it). The browser editor and the
//! downloads keep it ignored, where a peer closing a connection must be an error to handle, not
//! the end of the process.

use crate::cli::Command;
use crate::commands::bench::What;

/// Restores SIGPIPE's default action unless `command` talks over sockets.
pub fn install(command: &Command) {
    let sockets = match command {
        Command::Serve(_) | Command::FetchMerl(_) => true,
        Command::Bench(args) => matches!(args.what, What::Serve(_)),
        _ => false,
    };
    if !sockets {
        sigpipe::reset();
    }
}
