//! `experiments export-bsdf MATERIAL -o OUT.bsdf`: writes any material the commands accept (a
//! bundled name, a MERL `.binary` file such as the output of `decode`, `edit`, `interpolate` or
//! `recover`, an RGL `.bsdf` file) as an isotropic RGB tensor file of the RGL format (Dupuy &
//! Jakob 2018), which Mitsuba 3's and pbrt-v4's `measured` materials read
//! (`deepbrdf_data::rgl::export`). Prints the file's resolutions and the time the export took.
//! An existing output is never overwritten without `--force`.
use crate::args::data::CacheArg;
use anyhow::{bail, Context};
use deepbrdf_data::dataset::load_material;
use deepbrdf_data::rgl::{export, ExportResolution};
use deepbrdf_data::Progress;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The material: a MERL .binary file, an RGL .bsdf file or a bundled material.
    pub material: String,
    /// The RGL .bsdf file to write.
    #[arg(long, short = 'o', value_name = "FILE")]
    pub out: PathBuf,
    /// Replace an existing output file.
    #[arg(long)]
    pub force: bool,
    /// Incidence angles (theta_i), spaced uniformly in the microsurface's projected area.
    #[arg(long, value_name = "N", default_value_t = ExportResolution::default().theta_i)]
    pub theta_i: usize,
    /// Nodes of the microfacet distribution and projected-area tables (ndf, sigma).
    #[arg(long, value_name = "N", default_value_t = ExportResolution::default().ndf)]
    pub ndf: usize,
    /// Side of each incidence angle's VNDF table.
    #[arg(long, value_name = "N", default_value_t = ExportResolution::default().vndf)]
    pub vndf: usize,
    /// Side of each incidence angle's RGB and luminance tables.
    #[arg(long, value_name = "N", default_value_t = ExportResolution::default().rgb)]
    pub rgb: usize,
    /// Azimuths of incidence: only 1 (an isotropic file) can be written from a MERL table.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub phi_i: usize,
    #[command(flatten)]
    pub cache: CacheArg,
}

pub fn run(args: Args, _progress: &dyn Progress) -> anyhow::Result<()> {
    if args.phi_i != 1 {
        bail!(
            "--phi-i {}: an anisotropic file cannot be written for '{}' (a MERL table is \
             isotropic; only --phi-i 1 is possible)",
            args.phi_i,
            args.material
        );
    }
    if args.out.exists() && !args.force {
        bail!("{}: exists; not overwriting it (pass --force to replace it)", args.out.display());
    }
    let resolution =
        ExportResolution { theta_i: args.theta_i, ndf: args.ndf, vndf: args.vndf, rgb: args.rgb };
    let (name, table) = load_material(&args.material, &args.cache.cache())
        .with_context(|| format!("loading material '{}'", args.material))?;
    let start = Instant::now();
    let file = export(&table, &name, &resolution, &args.out)
        .with_context(|| format!("{}: cannot be exported", args.material))?;
    let seconds = start.elapsed().as_secs_f64();
    file.write(&args.out).with_context(|| format!("writing {}", args.out.display()))?;
    println!(
        "{name}: {} incidence angles, NDF {} nodes, VNDF {}x{}, RGB {}x{}; exported in \
         {seconds:.2} s on {} threads; wrote {}",
        resolution.theta_i,
        resolution.ndf,
        resolution.vndf,
        resolution.vndf,
        resolution.rgb,
        resolution.rgb,
        rayon::current_num_threads(),
        args.out.display()
    );
    Ok(())
}
