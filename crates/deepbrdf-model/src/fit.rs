//! The whole DeepBRDF pipeline on a set of measured BRDFs: the eq. (1) median reference of the
//! training tables, the mapped §3.2 layouts, training (§3.2) and the saved model artifact.

use std::path::Path;
use std::time::Duration;

use burn::prelude::*;
use deepbrdf_data::mapping::MedianReference;
use deepbrdf_data::{MerlTable, Progress};

use crate::autoencoder::artifact::{ModelArtifact, MODEL_DIR};
use crate::autoencoder::train::{train_within, TrainConfig};
use crate::codec::DeepBrdf;
use crate::error::Result;
use crate::streamed::StreamedTables;
use crate::training_set::TrainingSet;

/// Trains DeepBRDF on `tables` (named `names`, from the data source `label`), keeping the
/// checkpoint and log in `out_dir` and writing the model artifact to `out_dir/model`.
///
/// With `resume`, an interrupted run in `out_dir` is continued (a finished one is only
/// re-evaluated and re-saved); without it, an existing run there is an error. With a
/// `time_limit`, training stops at the end of the first epoch past it and the model written
/// has the epochs done so far (its provenance says how many); `resume` continues the run.
/// `streamed` BRDFs (an analytic corpus) train beside the tables without being held whole
/// (the `slice` network only); the reference is the tables' alone.
#[allow(clippy::too_many_arguments)]
pub fn fit(
    config: &TrainConfig,
    label: &str,
    names: &[String],
    tables: &[&MerlTable],
    streamed: Option<StreamedTables>,
    out_dir: &Path,
    resume: bool,
    time_limit: Option<Duration>,
    progress: &dyn Progress,
    device: &Device,
) -> Result<DeepBrdf> {
    config.validate()?;
    let reference = config.model.mapping_reference(&MedianReference::from_tables(tables)?);
    let mut set = TrainingSet::from_tables(label, names, tables, &reference)?;
    if let Some(streamed) = streamed {
        set = set.with_streamed(streamed)?;
    }
    let label = set.label().to_string();
    let trained = train_within(config, &set, out_dir, resume, time_limit, progress, device)?;
    drop(set);
    let artifact = ModelArtifact::from_trained(trained, reference, &label, names, device)?;
    artifact.save(&out_dir.join(MODEL_DIR))?;
    DeepBrdf::from_artifact(artifact, device)
}
