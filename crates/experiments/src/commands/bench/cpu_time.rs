//! The CPU time of this process, for the benchmarks that report CPU seconds beside wall time
//! (robust to other load on a shared machine).

/// CPU time (user + system) of this process so far, in seconds, from `/proc/self/stat`
/// (Linux; clock ticks assumed to be the usual 1/100 s). `None` elsewhere.
pub(super) fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let ticks = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}
