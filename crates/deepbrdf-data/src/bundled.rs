//! The 159 Neural BRDF materials bundled in the crate (Sztrajman et al. 2021, MIT licence), as
//! three named collections packed by `experiments pack-nbrdf` ([`crate::nbrdf::pack`]) and
//! embedded with `include_bytes!`, so a fresh clone works with no download:
//!
//! | collection | materials | measurements |
//! | --- | --- | --- |
//! | `merl` | 100 | MERL BRDF database (Matusik et al. 2003) |
//! | `nielsen2015` | 8 | Nielsen, Jensen & Ramamoorthi 2015 |
//! | `rgl` | 51 | RGL isotropic materials (Dupuy & Jakob 2018) |
//!
//! A fourth collection, `rgl-measured`, holds no networks: it is seven real RGL measurements
//! (raw `.bsdf` files, [`crate::rgl::bundled`]), converted to the MERL grid on first use.

use crate::error::{DataError, Result};
use crate::nbrdf::{unpack, Network};
use std::path::Path;
use std::sync::OnceLock;

/// A bundled collection of materials.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Collection {
    /// The 100 materials of the MERL BRDF database.
    Merl,
    /// The 8 materials of Nielsen et al. 2015.
    Nielsen2015,
    /// The 51 isotropic RGL materials.
    Rgl,
    /// Seven real RGL measurements ([`crate::rgl::bundled`]), not networks.
    RglMeasured,
}

impl Collection {
    /// The collections of networks, in lookup order.
    pub const ALL: [Collection; 3] = [Collection::Merl, Collection::Nielsen2015, Collection::Rgl];

    /// The collection's name: `merl`, `nielsen2015`, `rgl` or `rgl-measured`.
    pub fn name(self) -> &'static str {
        match self {
            Collection::Merl => "merl",
            Collection::Nielsen2015 => "nielsen2015",
            Collection::Rgl => "rgl",
            Collection::RglMeasured => crate::rgl::bundled::COLLECTION,
        }
    }

    /// Whether the collection holds raw measurements rather than networks.
    pub fn is_measured(self) -> bool {
        self == Collection::RglMeasured
    }

    /// The folder of JSON networks this collection is packed from (under the NBRDF data folder).
    pub fn source_folder(self) -> &'static str {
        match self {
            Collection::Merl => "merl",
            Collection::Nielsen2015 => "nielsen2015",
            Collection::Rgl => "rgl-isotropic",
            Collection::RglMeasured => "rgl-measured",
        }
    }

    /// The file name of the collection's pack: `<name>.nbrdf`.
    pub fn pack_file_name(self) -> String {
        format!("{}.nbrdf", self.name())
    }

    /// The embedded pack bytes (none for the measured collection).
    pub fn pack_bytes(self) -> Option<&'static [u8]> {
        match self {
            Collection::Merl => Some(include_bytes!("../assets/nbrdf/merl.nbrdf")),
            Collection::Nielsen2015 => Some(include_bytes!("../assets/nbrdf/nielsen2015.nbrdf")),
            Collection::Rgl => Some(include_bytes!("../assets/nbrdf/rgl.nbrdf")),
            Collection::RglMeasured => None,
        }
    }

    /// The collection's networks, sorted by name (unpacked once, then shared). An error for the
    /// measured collection, which has none.
    pub fn materials(self) -> Result<&'static [Network]> {
        static CELLS: [OnceLock<std::result::Result<Vec<Network>, String>>; 3] =
            [OnceLock::new(), OnceLock::new(), OnceLock::new()];
        let Some(pack) = self.pack_bytes() else {
            return Err(DataError::Invalid(format!(
                "{self} holds measurements, not networks (load its materials by name or as a dataset)"
            )));
        };
        let slot = &CELLS[self as usize];
        let unpacked = slot.get_or_init(|| {
            let origin = format!("<bundled {}>", self.pack_file_name());
            unpack(pack, Path::new(&origin)).map_err(|e| e.to_string())
        });
        match unpacked {
            Ok(nets) => Ok(nets),
            Err(e) => Err(DataError::Invalid(e.clone())),
        }
    }

    /// The names of the collection's materials, sorted.
    pub fn names(self) -> Result<Vec<&'static str>> {
        if self.is_measured() {
            return Ok(crate::rgl::bundled::names());
        }
        Ok(self.materials()?.iter().map(Network::name).collect())
    }

    /// The network called `name` in this collection, if any (never in the measured one).
    pub fn get(self, name: &str) -> Result<Option<&'static Network>> {
        if self.is_measured() {
            return Ok(None);
        }
        let nets = self.materials()?;
        Ok(nets.binary_search_by(|n| n.name().cmp(name)).ok().map(|i| &nets[i]))
    }
}

impl std::fmt::Display for Collection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Collection {
    type Err = DataError;

    /// Parses `merl`, `nielsen2015`, `rgl` (also `rgl-isotropic`) or `rgl-measured`, ignoring
    /// case.
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "merl" => Ok(Collection::Merl),
            "nielsen2015" => Ok(Collection::Nielsen2015),
            "rgl" | "rgl-isotropic" => Ok(Collection::Rgl),
            "rgl-measured" => Ok(Collection::RglMeasured),
            _ => Err(DataError::Invalid(format!(
                "unknown collection {s:?}: expected one of merl, nielsen2015, rgl, rgl-measured"
            ))),
        }
    }
}

/// Finds a bundled material by `name` (`chrome`) or `collection/name` (`merl/chrome`,
/// `rgl/cardboard_rgb`). Unknown names give an error listing close matches.
pub fn find_material(spec: &str) -> Result<(Collection, &'static Network)> {
    let (collections, name) = match spec.split_once('/') {
        Some((col, name)) => (vec![col.parse::<Collection>()?], name),
        None => (Collection::ALL.to_vec(), spec),
    };
    if collections.iter().any(|c| c.is_measured()) {
        return Err(DataError::Invalid(format!(
            "{spec:?} names a measurement, not a network (load it as a material, e.g. with \
             `experiments info {spec}`, or write a MERL file with `experiments convert`)"
        )));
    }
    for &col in &collections {
        if let Some(net) = col.get(name)? {
            return Ok((col, net));
        }
    }
    let mut candidates = Vec::new();
    for &col in &collections {
        for other in col.names()? {
            candidates.push((similarity_rank(name, other), format!("{col}/{other}")));
        }
    }
    candidates.sort();
    let close: Vec<String> =
        candidates.into_iter().filter(|(rank, _)| *rank <= 3).take(5).map(|(_, n)| n).collect();
    let scope = collections.iter().map(|c| c.name()).collect::<Vec<_>>().join(", ");
    let hint = if close.is_empty() {
        format!("(list them with `experiments info --list`; collections searched: {scope})")
    } else {
        format!("did you mean {}?", close.join(", "))
    };
    Err(DataError::Invalid(format!("no bundled material named {spec:?}: {hint}")))
}

/// How close `query` is to `name`: 0 when one contains the other, else the edit distance.
fn similarity_rank(query: &str, name: &str) -> usize {
    let (q, n) = (query.to_ascii_lowercase(), name.to_ascii_lowercase());
    if !q.is_empty() && (n.contains(&q) || q.contains(&n)) {
        return 0;
    }
    levenshtein(&q, &n)
}

/// Edit distance between two strings (insertions, deletions, substitutions).
fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != cb)).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collections_hold_100_8_51_materials() {
        assert_eq!(Collection::Merl.materials().expect("merl").len(), 100);
        assert_eq!(Collection::Nielsen2015.materials().expect("nielsen").len(), 8);
        assert_eq!(Collection::Rgl.materials().expect("rgl").len(), 51);
        assert!(Collection::Merl.get("chrome").expect("merl").is_some());
        assert!(Collection::Merl.get("cardboard").expect("merl").is_none());
    }

    #[test]
    fn names_parse_and_display() {
        for col in Collection::ALL.into_iter().chain([Collection::RglMeasured]) {
            assert_eq!(col.to_string().parse::<Collection>().expect("parse"), col);
        }
        assert!(Collection::RglMeasured.materials().is_err());
        assert_eq!(Collection::RglMeasured.names().expect("names").len(), 7);
        assert_eq!("RGL".parse::<Collection>().expect("parse"), Collection::Rgl);
        assert!("mer".parse::<Collection>().is_err());
    }

    #[test]
    fn materials_are_found_by_name_with_suggestions() {
        let (col, net) = find_material("chrome").expect("found");
        assert_eq!((col, net.name()), (Collection::Merl, "chrome"));
        let (col, net) = find_material("rgl/cardboard_rgb").expect("found");
        assert_eq!((col, net.name()), (Collection::Rgl, "cardboard_rgb"));
        let (col, _) = find_material("cardboard").expect("found");
        assert_eq!(col, Collection::Nielsen2015);
        let err = find_material("chrom").expect_err("unknown").to_string();
        assert!(err.contains("merl/chrome"), "{err}");
        let err = find_material("merl/cardboard_rgb").expect_err("wrong collection").to_string();
        assert!(err.contains("no bundled material"), "{err}");
        assert!(find_material("nope/chrome").is_err());
        let err = find_material("rgl-measured/paper_white_rgb").expect_err("no network");
        assert!(err.to_string().contains("measurement, not a network"), "{err}");
    }

    /// The 20 reference evaluations computed by the data's authors in float64 from the original
    /// Keras weights (`shared/data/nbrdf/reference-evaluations.json`, copied into tests-data).
    #[test]
    fn networks_agree_with_reference_evaluations() {
        let text = include_str!("../tests-data/reference-evaluations.json");
        let json: serde_json::Value = serde_json::from_str(text).expect("json");
        let cases = json["cases"].as_array().expect("cases");
        assert_eq!(cases.len(), 20);
        for case in cases {
            let col: Collection = case["collection"].as_str().expect("str").parse().expect("col");
            let name = case["name"].as_str().expect("name");
            let net = col.get(name).expect("bundle").expect("material");
            let angle = |k: &str| case[k].as_f64().expect("angle");
            let (th, td, pd) = (angle("theta_h"), angle("theta_d"), angle("phi_d"));
            let x = crate::nbrdf::input_vector(th, td, pd);
            for (a, b) in x.iter().zip(case["input"].as_array().expect("input")) {
                assert!((a - b.as_f64().expect("f64")).abs() < 1e-12, "{name}: input");
            }
            let rgb = net.evaluate(th, td, pd);
            for (c, want) in case["rgb"].as_array().expect("rgb").iter().enumerate() {
                let want = want.as_f64().expect("f64");
                let rel = (rgb[c] - want).abs() / want.abs();
                assert!(rel < 1e-5, "{col}/{name} ({th}, {td}, {pd}) c{c}: {} vs {want}", rgb[c]);
            }
        }
    }

    #[test]
    fn levenshtein_distances() {
        assert_eq!(levenshtein("kitten", "sitting"), 3);
        assert_eq!(levenshtein("", "abc"), 3);
        assert_eq!(levenshtein("chrome", "chrome"), 0);
    }
}
