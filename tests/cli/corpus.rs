//! CLI tests of `corpus`: the parameter file and the first tables are written, read back as the
//! library samples them, identical on 1 and 2 threads; existing files are not overwritten
//! without `--force`; bad counts are clean errors.
use crate::util;
use deepbrdf_data::corpus::{sample, CorpusReader};
use deepbrdf_data::MerlTable;

#[test]
fn corpus_writes_parameters_and_tables_deterministically() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("c");
    let args = ["corpus", "--count", "12", "--seed", "3", "--out", &util::s(&out), "--tables", "2"];
    let o = util::run_on_threads(dir.path(), &args, 2);
    assert!(o.status.success(), "{}", util::stderr(&o));
    let text = util::stdout(&o);
    assert!(
        text.contains("12 materials (seed 3)") && text.contains("bytes per material"),
        "{text}"
    );
    assert!(text.contains("2 tables") && text.contains("materials per second"), "{text}");
    let records: Vec<_> = CorpusReader::open(&out.join("corpus.jsonl"))
        .expect("open")
        .collect::<Result<_, _>>()
        .expect("a valid corpus");
    assert_eq!(records.len(), 12);
    for r in &records {
        assert_eq!(r.material, sample(3, r.index));
    }
    let mut names: Vec<String> = std::fs::read_dir(out.join("tables"))
        .expect("tables")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), 2);
    for (i, name) in names.iter().enumerate() {
        let m = sample(3, i as u64);
        assert_eq!(name, &format!("{i:06}-{}.binary", m.family));
        let table = MerlTable::read(out.join("tables").join(name)).expect("a MERL file");
        assert!(table == m.table().expect("tabulate"), "{name} is the material's table");
    }
    // Not overwritten without --force; the same bytes with it, on one thread.
    let first = std::fs::read(out.join("corpus.jsonl")).expect("read");
    util::assert_clean_failure(&util::run_on_threads(dir.path(), &args, 1), "not overwriting");
    let forced: Vec<&str> = args.iter().copied().chain(["--force"]).collect();
    let o = util::run_on_threads(dir.path(), &forced, 1);
    assert!(o.status.success(), "{}", util::stderr(&o));
    assert_eq!(std::fs::read(out.join("corpus.jsonl")).expect("read"), first);
    // Bad counts.
    let o = util::run(&["corpus", "--count", "0", "--out", &util::s(&dir.path().join("z"))]);
    util::assert_clean_failure(&o, "--count 0");
    let o = util::run(&["corpus", "--count", "2", "--tables", "3", "--out", &util::s(&out)]);
    util::assert_clean_failure(&o, "--tables 3");
}
