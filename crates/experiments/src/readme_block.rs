//! Rewrites one generated block of a markdown file (the README's results), between a begin and
//! an end marker, leaving everything else byte for byte as it was. The file is replaced through
//! a temporary file and a rename, so it is never left half written.

use anyhow::{bail, Context};
use std::path::Path;

/// `text` with the lines between the line holding `begin` and the line holding `end` replaced
/// by `block`. Each marker must appear exactly once, `begin` before `end`.
pub fn replace_block(text: &str, begin: &str, end: &str, block: &str) -> anyhow::Result<String> {
    let count = |m: &str| text.matches(m).count();
    if count(begin) != 1 || count(end) != 1 {
        bail!(
            "expected exactly one `{begin}` and one `{end}` (found {} and {}); add them around \
             the place the generated block should go",
            count(begin),
            count(end)
        );
    }
    let b = text.find(begin).unwrap_or_default();
    let e = text.find(end).unwrap_or_default();
    if e < b {
        bail!("`{end}` comes before `{begin}`");
    }
    // Keep the marker lines whole: cut after the begin marker's line and before the end
    // marker's line.
    let after_begin = text[b..].find('\n').map_or(text.len(), |i| b + i + 1);
    if after_begin > e {
        bail!("`{begin}` and `{end}` must be on separate lines");
    }
    let before_end = text[..e].rfind('\n').map_or(0, |i| i + 1);
    let mut out = String::with_capacity(text.len() + block.len());
    out.push_str(&text[..after_begin]);
    out.push_str(block);
    if !block.is_empty() && !block.ends_with('\n') {
        out.push('\n');
    }
    out.push_str(&text[before_end..]);
    Ok(out)
}

/// [`replace_block`] on the file at `path`, written back atomically.
pub fn update_file(path: &Path, begin: &str, end: &str, block: &str) -> anyhow::Result<()> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let new = replace_block(&text, begin, end, block)
        .with_context(|| format!("updating the generated block of {}", path.display()))?;
    deepbrdf_data::files::write_atomic(path, new.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const B: &str = "<!-- x:begin -->";
    const E: &str = "<!-- x:end -->";

    #[test]
    fn replaces_only_between_the_markers() {
        let text = format!("# Title\n\nintro\n{B}\nold\nlines\n{E}\ntail\n");
        let out = replace_block(&text, B, E, "new table").unwrap();
        assert_eq!(out, format!("# Title\n\nintro\n{B}\nnew table\n{E}\ntail\n"));
        // Idempotent, and an empty block leaves the markers adjacent.
        assert_eq!(replace_block(&out, B, E, "new table\n").unwrap(), out);
        assert_eq!(
            replace_block(&text, B, E, "").unwrap(),
            format!("# Title\n\nintro\n{B}\n{E}\ntail\n")
        );
    }

    #[test]
    fn refuses_missing_repeated_or_misordered_markers() {
        for bad in [
            "no markers".to_string(),
            format!("{B}\n"),
            format!("{E}\n{B}\n"),
            format!("{B}\n{B}\n{E}\n"),
            format!("{B} {E}\n"),
        ] {
            assert!(replace_block(&bad, B, E, "x").is_err(), "{bad}");
        }
    }

    #[test]
    fn updates_a_file_in_place() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("README.md");
        std::fs::write(&path, format!("a\n{B}\n{E}\nb\n")).unwrap();
        update_file(&path, B, E, "| t |").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), format!("a\n{B}\n| t |\n{E}\nb\n"));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no temp file left");
        std::fs::write(&path, "no markers").unwrap();
        let err = format!("{:#}", update_file(&path, B, E, "x").unwrap_err());
        assert!(err.contains("README.md") && err.contains(B), "{err}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "no markers");
    }
}
