//! Measured complex indices of refraction `eta + i k` of real metals at 630, 532 and 465 nm (R,
//! G, B), from `data/conductor-ior-rgb.tsv` (compiled in; its header names the sources: the
//! spectral tables shipped with Mitsuba 3, from luxpop.com and Palik's Handbook of Optical
//! Constants of Solids). The table's F0 column is checked against [`conductor_f0`].

use super::fresnel::Fresnel;
use crate::error::{DataError, Result};
use std::path::Path;
use std::sync::OnceLock;

/// The table's text, as vendored.
const TABLE: &str = include_str!("../../data/conductor-ior-rgb.tsv");
/// The table's path, for error messages.
const TABLE_PATH: &str = "crates/deepbrdf-data/data/conductor-ior-rgb.tsv";
/// The column names the parser expects.
const COLUMNS: [&str; 11] =
    ["symbol", "name", "eta_r", "eta_g", "eta_b", "k_r", "k_g", "k_b", "F0_r", "F0_g", "F0_b"];

/// One metal of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Conductor {
    /// Chemical symbol or formula (`Au`, `Cu2O`).
    pub symbol: String,
    /// English name (`gold`).
    pub name: String,
    /// Real part of the index per channel.
    pub eta: [f64; 3],
    /// Imaginary part (extinction coefficient) per channel.
    pub k: [f64; 3],
    /// Normal-incidence reflectance per channel as the table states it (4 decimals).
    pub f0: [f64; 3],
}

impl Conductor {
    /// The exact conductor Fresnel term of this metal.
    pub fn fresnel(&self) -> Fresnel {
        Fresnel::Conductor { eta: self.eta, k: self.k }
    }
}

/// The metals of the compiled-in table, parsed once.
pub fn conductors() -> Result<&'static [Conductor]> {
    static PARSED: OnceLock<std::result::Result<Vec<Conductor>, String>> = OnceLock::new();
    PARSED
        .get_or_init(|| parse(TABLE, Path::new(TABLE_PATH)).map_err(|e| e.to_string()))
        .as_deref()
        .map_err(|e| DataError::Invalid(e.clone()))
}

/// The metal with this symbol (case-insensitive) or name.
pub fn conductor(symbol_or_name: &str) -> Result<&'static Conductor> {
    let all = conductors()?;
    all.iter()
        .find(|c| c.symbol.eq_ignore_ascii_case(symbol_or_name) || c.name == symbol_or_name)
        .ok_or_else(|| {
            let known: Vec<&str> = all.iter().map(|c| c.symbol.as_str()).collect();
            DataError::Invalid(format!(
                "no metal '{symbol_or_name}' in the IOR table (known: {})",
                known.join(", ")
            ))
        })
}

/// Parses the tab-separated table: `#` comment lines, a header line with [`COLUMNS`], then one
/// metal a line. Errors name `origin` and the line.
pub fn parse(text: &str, origin: &Path) -> Result<Vec<Conductor>> {
    let mut rows =
        text.lines().enumerate().filter(|(_, l)| !l.starts_with('#') && !l.trim().is_empty());
    let bad = |line: usize, problem: String| {
        DataError::format(origin, format!("line {}: {problem}", line + 1))
    };
    let (n, header) = rows.next().ok_or_else(|| DataError::format(origin, "no header line"))?;
    if header.split('\t').collect::<Vec<_>>() != COLUMNS {
        return Err(bad(n, format!("the header is not {}", COLUMNS.join(" "))));
    }
    let mut metals = Vec::new();
    for (n, line) in rows {
        let fields: Vec<&str> = line.split('\t').collect();
        if fields.len() != COLUMNS.len() {
            return Err(bad(n, format!("{} fields, expected {}", fields.len(), COLUMNS.len())));
        }
        let mut numbers = [0.0; 9];
        for (i, field) in fields[2..].iter().enumerate() {
            let v: f64 = field
                .trim()
                .parse()
                .map_err(|_| bad(n, format!("{} '{field}' is not a number", COLUMNS[i + 2])))?;
            if !v.is_finite() || v < 0.0 || (i < 3 && v == 0.0) || (i >= 6 && v > 1.0) {
                return Err(bad(n, format!("{} = {v} is out of range", COLUMNS[i + 2])));
            }
            numbers[i] = v;
        }
        metals.push(Conductor {
            symbol: fields[0].to_string(),
            name: fields[1].to_string(),
            eta: [numbers[0], numbers[1], numbers[2]],
            k: [numbers[3], numbers[4], numbers[5]],
            f0: [numbers[6], numbers[7], numbers[8]],
        });
    }
    if metals.is_empty() {
        return Err(DataError::format(origin, "no metals"));
    }
    Ok(metals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::corpus::fresnel::conductor_f0;

    #[test]
    fn the_tables_f0_is_the_conductor_fresnel_at_normal_incidence() {
        let all = conductors().expect("the vendored table parses");
        assert!(all.len() >= 10, "{} metals", all.len());
        for m in all {
            let f0 = m.fresnel().normal();
            for c in 0..3 {
                assert!((f0[c] - conductor_f0(m.eta[c], m.k[c])).abs() < 1e-14);
                // The table rounds to 4 decimals (and its indices too).
                assert!((f0[c] - m.f0[c]).abs() < 5e-4, "{}: {f0:?} vs {:?}", m.symbol, m.f0);
            }
        }
        let gold = conductor("Au").expect("gold");
        assert_eq!(gold.name, "gold");
        assert!(gold.f0[0] > gold.f0[2]);
        assert_eq!(conductor("silver").expect("by name").symbol, "Ag");
        assert!(conductor("Xx").expect_err("unknown").to_string().contains("Au"));
    }

    #[test]
    fn bad_tables_are_refused_with_the_line() {
        let origin = Path::new("ior.tsv");
        let header = COLUMNS.join("\t");
        for (text, needle) in [
            ("", "no header"),
            ("a\tb\n", "header"),
            (&*format!("{header}\n"), "no metals"),
            (&*format!("{header}\nAu\tgold\t1\t1\n"), "line 2: 4 fields"),
            (
                &*format!("# c\n{header}\nAu\tgold\t1\t1\t1\t1\t1\tx\t0.5\t0.5\t0.5\n"),
                "line 3: k_b 'x'",
            ),
            (&*format!("{header}\nAu\tgold\t1\t1\t1\t1\t1\t1\t0.5\t0.5\t2\n"), "F0_b = 2"),
            (&*format!("{header}\nAu\tgold\t0\t1\t1\t1\t1\t1\t0.5\t0.5\t0.5\n"), "eta_r = 0"),
        ] {
            let err = parse(text, origin).expect_err(needle).to_string();
            assert!(err.contains("ior.tsv") && err.contains(needle), "{err}");
        }
    }
}
