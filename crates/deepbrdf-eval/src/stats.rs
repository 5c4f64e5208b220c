//! Summary statistics of per-material measures, one home for the harness' tables and the
//! commands' figures and benchmarks.
//!
//! Two kinds of mean, named for what they do with a value that is not finite: [`mean`] keeps
//! it (a results table must show that a measure failed somewhere), [`finite_mean`] and
//! [`finite_median`] leave it out (a figure's summary of the values that exist). The median of
//! an even count is the upper of the two middle values, as every median of this workspace's
//! reports.

/// The mean of all `values` (NaN when one is NaN); `None` when there is none.
pub fn mean(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let v: Vec<f64> = values.into_iter().collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// The mean of the finite `values`; NaN when there is none.
pub fn finite_mean(values: impl IntoIterator<Item = f64>) -> f64 {
    mean(values.into_iter().filter(|x| x.is_finite())).unwrap_or(f64::NAN)
}

/// The median of the finite `values` (the upper middle one of an even count); NaN when there
/// is none.
pub fn finite_median(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_means_differ_only_in_what_they_do_with_nan() {
        assert_eq!(mean([1.0, 2.0, 6.0]), Some(3.0));
        assert_eq!(mean(std::iter::empty()), None);
        assert!(mean([1.0, f64::NAN]).unwrap().is_nan());
        assert_eq!(finite_mean([1.0, f64::NAN, 3.0, f64::INFINITY]), 2.0);
        assert!(finite_mean([f64::NAN]).is_nan());
    }

    #[test]
    fn the_median_of_an_even_count_is_the_upper_middle_value() {
        assert_eq!(finite_median([3.0, 1.0, 2.0]), 2.0);
        assert_eq!(finite_median([4.0, 1.0, 3.0, 2.0]), 3.0);
        assert_eq!(finite_median([f64::NAN, 5.0, 1.0]), 5.0);
        assert!(finite_median(std::iter::empty()).is_nan());
    }
}
