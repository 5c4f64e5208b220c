//! Streamed, parallel tabulation of a corpus: records (from a corpus file or the sampler) are
//! tabulated in batches, materials of a batch in parallel (and each table's rows in parallel),
//! and handed on in index order; only one batch of tables (about 17.5 MB each) is in memory.

use super::file::Record;
use crate::error::Result;
use crate::{MerlTable, Progress};
use rayon::prelude::*;
use std::ops::Range;

/// The records of materials `range` of the corpus of `seed`, sampled on demand.
pub fn sampled(seed: u64, range: Range<u64>) -> impl Iterator<Item = Result<Record>> {
    range.map(move |i| Ok(Record::sampled(seed, i)))
}

/// Tabulates each record of `records` and calls `each(record, table)` in order; `batch`
/// materials (at least 1) are tabulated at a time, in parallel. Stops at the first error (of a
/// record, a tabulation or `each`). Advances `progress` by one a material (the caller starts and
/// finishes it). Returns the number of materials tabulated.
pub fn tabulate_each(
    records: impl Iterator<Item = Result<Record>>,
    batch: usize,
    progress: &dyn Progress,
    mut each: impl FnMut(&Record, MerlTable) -> Result<()>,
) -> Result<u64> {
    let mut records = records.peekable();
    let mut done = 0;
    while records.peek().is_some() {
        let chunk: Vec<Record> = records.by_ref().take(batch.max(1)).collect::<Result<_>>()?;
        let tables: Vec<Result<MerlTable>> = chunk.par_iter().map(|r| r.material.table()).collect();
        for (record, table) in chunk.iter().zip(tables) {
            each(record, table?)?;
            done += 1;
            progress.advance(1);
        }
    }
    Ok(done)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::file::{write_corpus, CorpusReader};
    use crate::merl::CELLS;
    use crate::Silent;

    #[test]
    fn a_streamed_corpus_gives_the_sampled_materials_tables_in_order() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("corpus.jsonl");
        write_corpus(&path, 9, 5, &Silent).expect("write");
        let mut from_file = vec![];
        let reader = CorpusReader::open(&path).expect("open");
        let n = tabulate_each(reader.skip(2), 2, &Silent, |r, t| {
            from_file.push((r.index, t));
            Ok(())
        })
        .expect("tabulate");
        assert_eq!(n, 3);
        let mut sampled_tables = vec![];
        tabulate_each(sampled(9, 2..5), 3, &Silent, |r, t| {
            sampled_tables.push((r.index, t));
            Ok(())
        })
        .expect("tabulate");
        assert_eq!(from_file.iter().map(|x| x.0).collect::<Vec<_>>(), [2, 3, 4]);
        assert!(from_file == sampled_tables, "the file and the sampler give the same tables");
        for (index, table) in &from_file {
            let valid = table.valid_cells();
            assert!(valid > CELLS / 2, "material {index}: {valid} valid cells");
            // Valid cells hold reflectance (>= 0), and the material reflects somewhere.
            let v = table.values();
            let negative = (0..CELLS).filter(|&c| table.is_valid(c) != (v[c] >= 0.0)).count();
            assert_eq!(negative, 0, "material {index}");
            assert!(v.iter().any(|&x| x > 0.0), "material {index}");
        }
    }

    #[test]
    fn errors_stop_the_stream() {
        let records =
            sampled(1, 0..4).chain(std::iter::once(Err(crate::DataError::Invalid("bad".into()))));
        let mut seen = 0;
        let err = tabulate_each(records, 8, &Silent, |_, _| {
            seen += 1;
            Ok(())
        });
        assert!(err.is_err() && seen == 0, "the failing batch is not tabulated");
    }
}
