//! `--time-limit SECONDS`: a training budget, parsed into a [`Duration`].

use std::time::Duration;

/// Parses a positive, finite number of seconds.
pub fn parse(s: &str) -> Result<Duration, String> {
    let seconds: f64 = s.trim().parse().map_err(|_| format!("'{s}' is not a number of seconds"))?;
    if !seconds.is_finite() || seconds <= 0.0 {
        return Err(format!("the time limit must be a positive number of seconds, not {s}"));
    }
    Duration::try_from_secs_f64(seconds).map_err(|e| format!("time limit {s}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_parse_and_nonsense_is_refused() {
        assert_eq!(parse("90").unwrap(), Duration::from_secs(90));
        assert_eq!(parse(" 0.5 ").unwrap(), Duration::from_millis(500));
        for bad in ["0", "-3", "inf", "NaN", "ten", "1e300"] {
            assert!(parse(bad).is_err(), "{bad}");
        }
    }
}
