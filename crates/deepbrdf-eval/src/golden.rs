//! Golden-section search (Kiefer 1953): the minimum of a unimodal function over an interval in a
//! fixed number of steps, each step keeping the golden ratio's share of the bracket. One home for
//! the fits that refine the best point of a grid.

/// The better of the two points left after `steps` golden-section steps for the minimum of `f`
/// over `[lo, hi]`, with its value: `(x, f(x))` (the lower point on a tie).
pub fn golden_section(
    mut f: impl FnMut(f64) -> f64,
    mut lo: f64,
    mut hi: f64,
    steps: usize,
) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..steps {
        if f1 < f2 {
            (hi, x2, f2) = (x2, x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            (lo, x1, f1) = (x1, x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    match f2 < f1 {
        true => (x2, f2),
        false => (x1, f1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_a_parabola_within_the_bracket() {
        let (x, fx) = golden_section(|x| (x - 0.3) * (x - 0.3) + 2.0, -1.0, 2.0, 40);
        assert!((x - 0.3).abs() < 1e-6 && (fx - 2.0).abs() < 1e-12, "{x} {fx}");
        // A minimum outside the bracket: its nearer end.
        let (x, _) = golden_section(|x| x, 1.0, 3.0, 40);
        assert!((x - 1.0).abs() < 1e-6, "{x}");
    }
}
