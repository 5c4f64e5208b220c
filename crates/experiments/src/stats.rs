//! Summary statistics of the measures the commands print and tabulate: the mean and the median
//! over the finite values (NaN when there is none), one home for the figures commands and the
//! benchmarks.

/// The mean of the finite values of `v`.
pub fn mean(v: impl IntoIterator<Item = f64>) -> f64 {
    let v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
    match v.is_empty() {
        true => f64::NAN,
        false => v.iter().sum::<f64>() / v.len() as f64,
    }
}

/// The median of the finite values of `v` (the upper one of an even count).
pub fn median(v: impl IntoIterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
