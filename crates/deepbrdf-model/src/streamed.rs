//! Training BRDFs that are streamed, never held whole: tables produced in order on demand (an
//! analytic corpus tabulated from its parameters, [`deepbrdf_data::corpus`]), each mapped with
//! the training set's eq. (1) reference into the §3.2 layout as it comes and let go once the
//! network's fixed parts have kept what they need of it (the `slice` network keeps its 540 x M
//! slice-basis coefficients, [`crate::autoencoder::slice::basis::project`], instead of its
//! 540 x 90 x 90 values). So a corpus of tens of thousands of materials trains beside the
//! measured collections in the memory of a few thousand coefficient vectors.

use std::path::{Path, PathBuf};

use deepbrdf_data::corpus::{tabulate_each, CorpusReader};
use deepbrdf_data::layout::{mask_layout, to_layout, LAYOUT_VALUES};
use deepbrdf_data::mapping::log_relative;
use deepbrdf_data::{MerlTable, Progress};
use rayon::prelude::*;
use sha2::{Digest, Sha256};

use crate::error::{ModelError, Result};

/// Corpus materials tabulated at a time (in parallel).
const TABULATED_AT_ONCE: usize = 8;

/// Where the streamed tables come from.
#[derive(Debug, Clone)]
enum Source {
    /// The first `count` materials of a corpus file (`experiments corpus`).
    Corpus { path: PathBuf, count: u64 },
}

/// A stream of training BRDFs, replayed from its start each time it is read.
#[derive(Debug, Clone)]
pub struct StreamedTables {
    label: String,
    count: usize,
    identity: String,
    source: Source,
}

impl StreamedTables {
    /// The first `count` materials of the corpus file `path` (all of them without a count),
    /// tabulated on the MERL grid as they are read ([`tabulate_each`]). The file's records are
    /// hashed once here, so a resumed run can check it streams the same materials.
    pub fn corpus(path: &Path, count: Option<u64>) -> Result<Self> {
        let reader = CorpusReader::open(path)?;
        let header = reader.header().clone();
        let count = count.map_or(header.count, |n| n.min(header.count));
        let mut hasher = Sha256::new();
        hasher.update(format!("corpus seed {} count {count}", header.seed).as_bytes());
        for record in reader.take(count as usize) {
            let record = record?;
            let line = serde_json::to_string(&record).map_err(|e| {
                ModelError::Invalid(format!("{}: record {}: {e}", path.display(), record.index))
            })?;
            hasher.update(line.as_bytes());
        }
        let name = path
            .file_name()
            .map_or_else(|| path.display().to_string(), |f| f.to_string_lossy().into_owned());
        Ok(Self {
            label: format!("corpus({count} of {name})"),
            count: usize::try_from(count)
                .map_err(|_| ModelError::Invalid(format!("{}: too many", path.display())))?,
            identity: hex::encode(&hasher.finalize()[..16]),
            source: Source::Corpus { path: path.to_path_buf(), count },
        })
    }

    /// What the stream holds, for a data label (`corpus(N of FILE)`).
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The number of BRDFs the stream gives.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether the stream gives no BRDF.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// A digest of the stream's content (for the training set's fingerprint).
    pub fn identity(&self) -> &str {
        &self.identity
    }

    /// Calls `each(index, name, table)` for every BRDF of the stream, in order, advancing
    /// `progress` by one a BRDF (the caller starts and finishes it).
    pub fn for_each(
        &self,
        progress: &dyn Progress,
        mut each: impl FnMut(usize, &str, MerlTable) -> Result<()>,
    ) -> Result<()> {
        match &self.source {
            Source::Corpus { path, count } => {
                let reader = CorpusReader::open(path)?;
                let mut index = 0;
                let mut failed = None;
                let n = tabulate_each(
                    reader.take(*count as usize),
                    TABULATED_AT_ONCE,
                    progress,
                    |record, table| {
                        let name = format!("corpus/{:06}-{}", record.index, record.material.family);
                        match each(index, &name, table) {
                            Ok(()) => {
                                index += 1;
                                Ok(())
                            }
                            Err(e) => {
                                failed = Some(e);
                                Err(deepbrdf_data::DataError::Invalid("stopped".into()))
                            }
                        }
                    },
                );
                if let Some(e) = failed {
                    return Err(e);
                }
                let n = n?;
                if n != *count {
                    return Err(ModelError::Invalid(format!(
                        "{}: {n} materials read, {count} expected",
                        path.display()
                    )));
                }
                Ok(())
            }
        }
    }
}

/// `table` mapped with eq. (1) relative to `reference` (in layout order, as
/// [`crate::TrainingSet::reference_layout`]) into the §3.2 layout, invalid cells 0, and its
/// number of valid values: the same values as [`crate::TrainingSet::from_tables`] gives it.
pub fn mapped_layout(table: &MerlTable, reference: &[f32]) -> Result<(Vec<f32>, f64)> {
    if reference.len() != LAYOUT_VALUES {
        return Err(ModelError::Invalid(format!(
            "a reference of {} values, expected {LAYOUT_VALUES}",
            reference.len()
        )));
    }
    let values = to_layout(table.values());
    let mask = mask_layout(&table.mask());
    let mut out = vec![0f32; LAYOUT_VALUES];
    out.par_iter_mut()
        .zip(values.par_iter().zip(mask.par_iter()))
        .zip(reference.par_iter())
        .for_each(|((o, (&rho, &m)), &r)| {
            if m != 0.0 {
                *o = log_relative(f64::from(rho), f64::from(r)) as f32;
            }
        });
    let valid = mask.iter().map(|&m| f64::from(m)).sum();
    Ok((out, valid))
}

#[cfg(test)]
mod tests {
    use super::*;
    use deepbrdf_data::corpus::write_corpus;
    use deepbrdf_data::mapping::MedianReference;
    use deepbrdf_data::Silent;

    #[test]
    fn a_corpus_streams_its_tables_mapped_as_a_training_set_maps_them() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("corpus.jsonl");
        write_corpus(&path, 3, 4, &Silent).expect("write");
        let stream = StreamedTables::corpus(&path, Some(3)).expect("open");
        assert_eq!((stream.len(), stream.label()), (3, "corpus(3 of corpus.jsonl)"));
        let mut tables = vec![];
        let mut names = vec![];
        stream
            .for_each(&Silent, |i, name, t| {
                assert_eq!(i, tables.len());
                names.push(name.to_string());
                tables.push(t);
                Ok(())
            })
            .expect("stream");
        assert_eq!(tables.len(), 3);
        let refs: Vec<&MerlTable> = tables.iter().collect();
        let reference = MedianReference::from_tables(&refs).expect("reference");
        let set = crate::TrainingSet::from_tables("t", &names, &refs, &reference).expect("set");
        for (i, t) in tables.iter().enumerate() {
            let (layout, valid) =
                mapped_layout(t, set.reference_layout().expect("reference")).expect("map");
            assert!(layout == set.input(i), "material {i}: the same mapped values");
            assert_eq!(valid, set.valid_values(i));
        }
        // The identity changes with the materials streamed.
        let all = StreamedTables::corpus(&path, None).expect("open");
        assert_eq!(all.len(), 4);
        assert_ne!(all.identity(), stream.identity());
        // An error of the consumer stops the stream and is the one returned.
        let mut seen = 0;
        let err = stream
            .for_each(&Silent, |_, _, _| {
                seen += 1;
                Err(ModelError::Invalid("consumer".into()))
            })
            .expect_err("stops");
        assert!(err.to_string().contains("consumer") && seen == 1, "{err}");
    }

    #[test]
    fn a_streamed_corpus_trains_the_slice_network_beside_the_held_tables() {
        use crate::augmentation::AugmentationConfig;
        use crate::autoencoder::train::{evaluate, train, TrainConfig};
        use crate::autoencoder::{Architecture, AutoencoderConfig, SliceConfig};
        use crate::train::adam;
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("corpus.jsonl");
        write_corpus(&path, 11, 6, &Silent).expect("write");
        let held: Vec<MerlTable> = (0..3)
            .map(|m| {
                MerlTable::from_fn(|h, d, _| {
                    let v = 0.02 * (m + 1) as f32 + 0.001 * (h as f32 - d as f32).abs();
                    [v, (1.0 + 0.3 * m as f32) * v, 0.6 * v]
                })
            })
            .collect();
        let refs: Vec<&MerlTable> = held.iter().collect();
        let reference = MedianReference::from_tables(&refs).expect("reference");
        let names: Vec<String> = (0..3).map(|i| format!("held{i}")).collect();
        let set = crate::TrainingSet::from_tables("held", &names, &refs, &reference).expect("set");
        let stream = StreamedTables::corpus(&path, None).expect("corpus");
        let with_stream = set.clone().with_streamed(stream.clone()).expect("streamed");
        assert_eq!(with_stream.label(), "held+corpus(6 of corpus.jsonl)");
        assert_ne!(with_stream.fingerprint(), set.fingerprint());
        let layers = SliceConfig::new()
            .with_directions(12)
            .with_components(3)
            .with_hidden(Some(16))
            .with_augmentation(AugmentationConfig::new());
        let config =
            TrainConfig::new(AutoencoderConfig::new(2, Architecture::Slice(layers)), adam())
                .with_learning_rate(1e-2)
                .with_epochs(30)
                .with_batch_size(2)
                .with_seed(5)
                .with_checkpoint_seconds(0.0);
        let device = Default::default();
        let (a, b) = (tempfile::tempdir().expect("a"), tempfile::tempdir().expect("b"));
        let plain = train(&config, &set, a.path(), false, &Silent, &device).expect("plain");
        let streamed =
            train(&config, &with_stream, b.path(), false, &Silent, &device).expect("run");
        assert_eq!(streamed.per_material_mse.len(), 3, "scored on the held BRDFs");
        // The corpus' materials, never held by the set, are represented better by the network
        // that streamed them.
        let mut corpus = vec![];
        stream
            .for_each(&Silent, |_, name, t| Ok(corpus.push((name.to_string(), t))))
            .expect("read");
        let corpus_refs: Vec<&MerlTable> = corpus.iter().map(|(_, t)| t).collect();
        let corpus_names: Vec<String> = corpus.iter().map(|(n, _)| n.clone()).collect();
        let corpus_set =
            crate::TrainingSet::from_tables("c", &corpus_names, &corpus_refs, &reference)
                .expect("corpus set");
        let mean = |m: &crate::Autoencoder| {
            let e = evaluate(m, &corpus_set, 2, &Silent).expect("evaluate");
            e.iter().sum::<f64>() / e.len() as f64
        };
        let (without, with) = (mean(&plain.model), mean(&streamed.model));
        assert!(with < 0.8 * without, "corpus MSE {with} streamed vs {without} not");
        // More passes over the held BRDFs weigh them against the stream: they end better
        // represented. One pass is written as before the setting existed.
        let held_mean = |t: &crate::autoencoder::train::Trained| {
            t.per_material_mse.iter().sum::<f64>() / t.per_material_mse.len() as f64
        };
        let json = serde_json::to_string(&config).expect("json");
        assert!(!json.contains("held_passes"), "{json}");
        let mut weighted = config.clone();
        if let Architecture::Slice(layers) = &mut weighted.model.architecture {
            layers.augmentation.held_passes = 4;
        }
        assert!(serde_json::to_string(&weighted).expect("json").contains("\"held_passes\":4"));
        let c = tempfile::tempdir().expect("c");
        let heavier = train(&weighted, &with_stream, c.path(), false, &Silent, &device).expect("4");
        let (one, four) = (held_mean(&streamed), held_mean(&heavier));
        assert!(four < 0.8 * one, "held MSE {four} with 4 passes vs {one} with 1");
        // A finished run resumed with other data is refused, not silently re-used.
        let err = train(&config, &set, b.path(), true, &Silent, &device).expect_err("other data");
        assert!(err.to_string().contains("data"), "{err}");
    }
}
