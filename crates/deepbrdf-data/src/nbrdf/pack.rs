//! The compact binary pack of a collection of [`Network`]s (the `.nbrdf` files bundled in the
//! crate). Little-endian throughout:
//!
//! ```text
//! magic     8 bytes  "NBRDFPK\0"
//! version   u32      PACK_VERSION
//! count     u32      number of networks
//! sha256    32 bytes SHA-256 of the payload
//! payload:  per network, sorted by name:
//!             name length u16, name (UTF-8), PARAMETERS x f32 (W1, b1, W2, b2, W3, b3)
//! ```
//!
//! A pack is a pure function of the networks (no timestamps, sorted order), so packing the same
//! JSON folder twice gives identical bytes.

use super::network::{Network, PARAMETERS};
use crate::error::{DataError, Result};
use sha2::{Digest, Sha256};
use std::path::Path;

/// Magic bytes opening a pack.
pub const PACK_MAGIC: [u8; 8] = *b"NBRDFPK\0";
/// Version of the pack layout.
pub const PACK_VERSION: u32 = 1;
/// Bytes before the payload.
const HEADER: usize = 8 + 4 + 4 + 32;
/// More networks than this in one pack means a corrupt count.
const MAX_NETWORKS: usize = 100_000;

/// Serialises `networks` (sorted by name) into a pack. Rejects duplicate or over-long names.
pub fn pack(networks: &[Network]) -> Result<Vec<u8>> {
    let mut sorted: Vec<&Network> = networks.iter().collect();
    sorted.sort_by(|a, b| a.name().cmp(b.name()));
    if let Some(w) = sorted.windows(2).find(|w| w[0].name() == w[1].name()) {
        return Err(DataError::Invalid(format!("two networks are named {}", w[0].name())));
    }
    let mut payload = Vec::with_capacity(sorted.len() * (PARAMETERS * 4 + 34));
    for net in sorted {
        let name = net.name().as_bytes();
        let len = u16::try_from(name.len())
            .map_err(|_| DataError::Invalid(format!("network name too long: {}", net.name())))?;
        payload.extend(len.to_le_bytes());
        payload.extend(name);
        payload.extend(net.parameter_bytes());
    }
    let count = u32::try_from(networks.len())
        .map_err(|_| DataError::Invalid("too many networks for one pack".into()))?;
    let mut out = Vec::with_capacity(HEADER + payload.len());
    out.extend(PACK_MAGIC);
    out.extend(PACK_VERSION.to_le_bytes());
    out.extend(count.to_le_bytes());
    out.extend(Sha256::digest(&payload));
    out.extend(payload);
    Ok(out)
}

/// Parses a pack; `origin` names it in errors (a path or a bundled collection).
pub fn unpack(bytes: &[u8], origin: &Path) -> Result<Vec<Network>> {
    let fail = |problem: String| DataError::format(origin, problem);
    if bytes.len() < HEADER {
        return Err(fail(format!("{} bytes is too short for a NBRDF pack header", bytes.len())));
    }
    if bytes[..8] != PACK_MAGIC {
        return Err(fail("not a NBRDF pack (wrong magic bytes)".into()));
    }
    let u32_at =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let version = u32_at(8);
    if version != PACK_VERSION {
        return Err(fail(format!("pack version {version}, this build reads {PACK_VERSION}")));
    }
    let count = u32_at(12) as usize;
    if count > MAX_NETWORKS {
        return Err(fail(format!("absurd network count {count}")));
    }
    let payload = &bytes[HEADER..];
    if Sha256::digest(payload).as_slice() != &bytes[16..48] {
        return Err(fail("checksum mismatch: the pack is corrupt or truncated".into()));
    }
    let mut networks = Vec::with_capacity(count);
    let mut at = 0usize;
    for n in 0..count {
        let truncated = || fail(format!("payload ends inside network {n}"));
        let len_bytes = payload.get(at..at + 2).ok_or_else(truncated)?;
        let len = u16::from_le_bytes([len_bytes[0], len_bytes[1]]) as usize;
        at += 2;
        let name = payload.get(at..at + len).ok_or_else(truncated)?;
        let name = std::str::from_utf8(name)
            .map_err(|_| fail(format!("name of network {n} is not UTF-8")))?;
        at += len;
        let raw = payload.get(at..at + PARAMETERS * 4).ok_or_else(truncated)?;
        at += PARAMETERS * 4;
        let params: Vec<f32> =
            raw.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        networks.push(Network::from_parameters(name, &params).map_err(|e| fail(e.to_string()))?);
    }
    if at != payload.len() {
        return Err(fail(format!("{} trailing bytes after {count} networks", payload.len() - at)));
    }
    Ok(networks)
}

/// Reads every `*.json` network in `dir` (sorted by file name) and packs them. Each network's
/// `name` must equal its file stem.
pub fn pack_json_folder(dir: &Path) -> Result<Vec<u8>> {
    let networks = read_json_folder(dir)?;
    pack(&networks)
}

/// Reads every `*.json` network in `dir`, sorted by file name.
pub fn read_json_folder(dir: &Path) -> Result<Vec<Network>> {
    let entries = std::fs::read_dir(dir).map_err(|e| DataError::io(dir, e))?;
    let mut paths = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| DataError::io(dir, e))?.path();
        if path.extension().is_some_and(|e| e == "json") {
            paths.push(path);
        }
    }
    if paths.is_empty() {
        return Err(DataError::format(dir, "contains no *.json network files"));
    }
    paths.sort();
    paths
        .iter()
        .map(|path| {
            let net = Network::read_json(path)?;
            let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
            if net.name() != stem {
                return Err(DataError::format(
                    path,
                    format!("network is named {:?} but the file is {stem}.json", net.name()),
                ));
            }
            Ok(net)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn net(name: &str, seed: f32) -> Network {
        let params: Vec<f32> = (0..PARAMETERS).map(|i| (i as f32 * seed).sin()).collect();
        Network::from_parameters(name, &params).expect("valid")
    }

    #[test]
    fn pack_round_trip_sorted_and_reproducible() {
        let nets = vec![net("b", 0.3), net("a", 0.7), net("c-3", 1.1)];
        let bytes = pack(&nets).expect("pack");
        assert_eq!(bytes.len(), HEADER + 3 * (2 + PARAMETERS * 4) + 1 + 1 + 3);
        let back = unpack(&bytes, Path::new("test.nbrdf")).expect("unpack");
        let names: Vec<&str> = back.iter().map(|n| n.name()).collect();
        assert_eq!(names, ["a", "b", "c-3"]);
        assert_eq!(back[0], nets[1]);
        assert_eq!(back[2], nets[2]);
        let reversed: Vec<Network> = nets.iter().rev().cloned().collect();
        assert_eq!(pack(&reversed).expect("pack"), bytes);
    }

    #[test]
    fn corrupt_packs_are_rejected() {
        let bytes = pack(&[net("a", 0.3), net("b", 0.5)]).expect("pack");
        let origin = Path::new("x.nbrdf");
        let err = |b: &[u8]| unpack(b, origin).expect_err("must fail").to_string();
        assert!(err(&bytes[..10]).contains("too short"));
        assert!(err(&bytes[..bytes.len() - 1]).contains("checksum"));
        let mut flipped = bytes.clone();
        flipped[HEADER + 100] ^= 1;
        assert!(err(&flipped).contains("checksum"));
        let mut magic = bytes.clone();
        magic[0] = b'X';
        assert!(err(&magic).contains("magic"));
        let mut count = bytes.clone();
        count[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(err(&count).contains("absurd"));
        let mut fewer = bytes.clone();
        fewer[12..16].copy_from_slice(&1u32.to_le_bytes());
        assert!(err(&fewer).contains("trailing"));
        assert!(err(&fewer).contains("x.nbrdf"));
        assert!(pack(&[net("a", 0.3), net("a", 0.5)]).is_err());
    }

    #[test]
    fn mutated_packs_are_rejected_or_read_never_a_panic() {
        use crate::testing::mutate::{fuzz, inputs, Focus};
        // The smallest bundled pack, and a three-network one, as seeds.
        let corpus = vec![
            include_bytes!("../../assets/nbrdf/nielsen2015.nbrdf").to_vec(),
            pack(&[net("b", 0.3), net("a", 0.7), net("c-3", 1.1)]).expect("pack"),
        ];
        let origin = Path::new("fuzz.nbrdf");
        let n = inputs(1_000);
        let focus = Focus { header: HEADER + 64, header_share: 0.7 };
        // As mutated: the checksum catches payload damage.
        let raw = fuzz(&corpus, 11, n, focus, |b| unpack(b, origin));
        // With the checksum recomputed over the mutated payload, so the payload parser itself
        // (name lengths, UTF-8, counts, trailing bytes, parameter values) sees the damage.
        let resealed = fuzz(&corpus, 12, n, focus, |b| {
            let mut b = b.to_vec();
            if b.len() >= HEADER {
                let sum = Sha256::digest(&b[HEADER..]);
                b[16..48].copy_from_slice(&sum);
            }
            unpack(&b, origin)
        });
        eprintln!("NBRDF pack reader: raw {raw:?}, resealed {resealed:?}");
        for report in [&raw, &resealed] {
            assert!(report.panics.is_empty(), "panics: {:?}", report.panics);
        }
        assert!(resealed.rejected > 0 && resealed.accepted > 0, "{resealed:?}");
    }
}
