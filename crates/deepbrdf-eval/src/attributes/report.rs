//! The table of estimated attributes over a set of materials: one row per material (the 7
//! values, the fit's log-space error and, when measured, the image RelAE of the analytic fit
//! against the measurement), as CSV and as a markdown table with a summary line.

use super::{AttributeFit, ATTRIBUTE_NAMES};
use crate::error::Result;
use crate::harness::csv_field;
use std::fmt::Write;
use std::path::Path;

/// One material's row.
#[derive(Clone, Debug, PartialEq)]
pub struct AttributeRow {
    pub material: String,
    pub fit: AttributeFit,
    /// Image RelAE of the fit's render against the measurement's ([`crate::metrics::ImageRelae`]).
    pub image_relae: Option<f64>,
    /// Wall time of the fit.
    pub seconds: f64,
}

/// `material, 7 attributes, log_rmse, image_relae (empty when not measured), cells, seconds`.
pub fn csv(rows: &[AttributeRow]) -> String {
    let mut out =
        format!("material,{},log_rmse,image_relae,cells,seconds\n", ATTRIBUTE_NAMES.join(","));
    for r in rows {
        let values: Vec<String> =
            r.fit.attributes.to_array().iter().map(|v| format!("{v:.6}")).collect();
        let relae = r.image_relae.map(|v| format!("{v:.6}")).unwrap_or_default();
        let _ = writeln!(
            out,
            "{},{},{:.6},{relae},{},{:.4}",
            csv_field(&r.material),
            values.join(","),
            r.fit.log_rmse,
            r.fit.cells,
            r.seconds
        );
    }
    out
}

/// Writes [`csv`] to `path` atomically (temporary file, fsync, rename).
pub fn write_csv(path: &Path, rows: &[AttributeRow]) -> Result<()> {
    Ok(deepbrdf_data::files::write_atomic(path, csv(rows).as_bytes())?)
}

/// A markdown table of the rows.
pub fn markdown(rows: &[AttributeRow]) -> String {
    let mut out = String::from(
        "| material | diffuse (RGB) | specular (RGB) | roughness | log RMSE | image RelAE |\n\
         |---|---|---|---:|---:|---:|\n",
    );
    let rgb = |v: [f64; 3]| format!("{:.3}, {:.3}, {:.3}", v[0], v[1], v[2]);
    for r in rows {
        let a = &r.fit.attributes;
        let relae = r.image_relae.map(|v| format!("{v:.4}")).unwrap_or_else(|| "-".into());
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.4} | {:.4} | {relae} |",
            r.material,
            rgb(a.diffuse),
            rgb(a.specular),
            a.roughness,
            r.fit.log_rmse
        );
    }
    out
}

/// Mean, median and largest of a non-empty list.
fn stats(mut v: Vec<f64>) -> Option<(f64, f64, f64)> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let n = v.len();
    let median = if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) };
    Some((mean, median, v[n - 1]))
}

/// One line: the number of materials, mean / median / largest log RMSE, image RelAE (when
/// measured) and fit time.
pub fn summary(rows: &[AttributeRow]) -> String {
    let mut out = format!("{} materials", rows.len());
    let mut part = |label: &str, v: Vec<f64>, digits: usize| {
        if let Some((mean, median, max)) = stats(v) {
            let _ = write!(
                out,
                "; {label} mean {mean:.digits$}, median {median:.digits$}, max {max:.digits$}"
            );
        }
    };
    part("log RMSE", rows.iter().map(|r| r.fit.log_rmse).collect(), 4);
    part("image RelAE", rows.iter().filter_map(|r| r.image_relae).collect(), 4);
    part("fit seconds", rows.iter().map(|r| r.seconds).collect(), 3);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attributes::Attributes;

    #[test]
    fn csv_markdown_and_summary_carry_every_row() {
        let a = Attributes { diffuse: [0.1, 0.2, 0.3], specular: [0.4, 0.5, 0.6], roughness: 0.07 };
        let row = |name: &str, relae: Option<f64>, e: f64| AttributeRow {
            material: name.into(),
            fit: AttributeFit { attributes: a, log_rmse: e, cells: 1000 },
            image_relae: relae,
            seconds: 0.2,
        };
        let rows =
            vec![row("x, y", Some(0.1), 0.01), row("z", None, 0.03), row("w", Some(0.3), 0.02)];
        let csv = csv(&rows);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 4);
        assert!(
            lines[0].starts_with("material,diffuse_r,") && lines[0].contains("roughness,log_rmse")
        );
        assert!(
            lines[1].starts_with("\"x, y\",0.100000,0.200000,0.300000,0.400000"),
            "{}",
            lines[1]
        );
        assert!(lines[2].contains(",0.030000,,1000,"), "{}", lines[2]);
        let md = markdown(&rows);
        assert!(
            md.contains("| z | 0.100, 0.200, 0.300 | 0.400, 0.500, 0.600 | 0.0700 | 0.0300 | - |"),
            "{md}"
        );
        let s = summary(&rows);
        assert!(s.starts_with("3 materials"), "{s}");
        assert!(s.contains("log RMSE mean 0.0200, median 0.0200, max 0.0300"), "{s}");
        assert!(s.contains("image RelAE mean 0.2000, median 0.2000, max 0.3000"), "{s}");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.csv");
        write_csv(&path, &rows).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), csv);
    }
}
