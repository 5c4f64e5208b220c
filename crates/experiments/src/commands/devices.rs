//! `experiments devices`: which compute devices this binary can use.
use deepbrdf_data::Progress;
use deepbrdf_model::DeviceKind;

#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    for kind in DeviceKind::ALL {
        let state = if kind.is_compiled() { "available" } else { "not compiled in" };
        println!("{:8} {state}", kind.name());
    }
    Ok(())
}
