//! Epoch order and batching: the examples of epoch `e` in a permutation drawn from
//! `ChaCha8Rng(seed)` on stream `e`, cut into consecutive batches. It depends on nothing but
//! the seed, the epoch and the number of examples, so a resumed run replays the same batches.

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The order of the examples in epoch `epoch` (0-based): a permutation of `0..n` depending only
/// on the seed and the epoch.
pub fn epoch_order(seed: u64, epoch: usize, n: usize) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(epoch as u64);
    let mut order: Vec<usize> = (0..n).collect();
    order.shuffle(&mut rng);
    order
}

/// Batches per epoch of `n` examples in batches of `batch_size` (the last one may be short).
pub fn batches_per_epoch(n: usize, batch_size: usize) -> usize {
    n.div_ceil(batch_size.max(1))
}

/// Batch `batch` (0-based) of `order`.
pub fn batch_of(order: &[usize], batch: usize, batch_size: usize) -> &[usize] {
    let start = (batch * batch_size).min(order.len());
    &order[start..(start + batch_size).min(order.len())]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn epoch_orders_are_seeded_permutations() {
        let a = epoch_order(1, 0, 10);
        assert_eq!(a, epoch_order(1, 0, 10));
        assert_ne!(a, epoch_order(1, 1, 10));
        assert_ne!(a, epoch_order(2, 0, 10));
        let mut sorted = a.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..10).collect::<Vec<_>>());
    }

    #[test]
    fn batches_cover_an_epoch_once_with_a_short_last_one() {
        let order = epoch_order(3, 2, 7);
        assert_eq!(batches_per_epoch(7, 3), 3);
        let batches: Vec<&[usize]> = (0..3).map(|b| batch_of(&order, b, 3)).collect();
        assert_eq!(batches.iter().map(|b| b.len()).collect::<Vec<_>>(), [3, 3, 1]);
        assert_eq!(batches.concat(), order);
        assert_eq!(batches_per_epoch(6, 3), 2);
    }
}
