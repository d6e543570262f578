//! Parallel reductions whose result does not depend on the number of threads or on
//! scheduling. rayon's `sum`, `fold` and `reduce` split the work where threads happen to steal
//! it, so floating-point sums round differently from run to run (outputs then differ at the
//! 1e-13 mm level). Here the items are cut into blocks of a fixed size, each block is folded
//! in item order, and the blocks' results are merged in block order: the same input gives the
//! same bits every time.

use rayon::prelude::*;
use std::ops::Range;

/// Items per block: large enough that a block is worth a task, fixed so that the grouping of
/// the additions never changes.
pub const BLOCK: usize = 1 << 12;

/// `per_block` of each block of `0..len` (in parallel), in block order.
pub fn blocks<T: Send>(len: usize, per_block: impl Fn(Range<usize>) -> T + Sync + Send) -> Vec<T> {
    (0..len.div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| per_block(b * BLOCK..((b + 1) * BLOCK).min(len)))
        .collect()
}

/// Folds the items `0..len` with `fold` starting from `init()` in each block, then merges the
/// blocks' results in order with `merge`: a deterministic parallel `fold().reduce()`.
pub fn fold<T: Send>(
    len: usize,
    init: impl Fn() -> T + Sync + Send,
    fold: impl Fn(T, usize) -> T + Sync + Send,
    merge: impl Fn(T, T) -> T,
) -> T {
    blocks(len, |range| range.fold(init(), &fold)).into_iter().fold(init(), merge)
}

/// The sum of `f(i)` over `0..len`, deterministic (see the module documentation).
pub fn sum(len: usize, f: impl Fn(usize) -> f64 + Sync + Send) -> f64 {
    fold(len, || 0.0, |s, i| s + f(i), |a, b| a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_bits_whatever_the_thread_count() {
        let n = 1_000_003;
        let f = |i: usize| ((i * 7919 % 1000) as f64).sqrt() * 1e-3 + 1e10 * (i % 2) as f64;
        let runs: Vec<u64> = [1, 2, 3, 7]
            .map(|threads| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| sum(n, f)).to_bits()
            })
            .into();
        assert!(runs.windows(2).all(|w| w[0] == w[1]), "{runs:?}");
        // And the same as adding block by block in order, by hand.
        let by_hand = (0..n.div_ceil(BLOCK))
            .map(|b| (b * BLOCK..((b + 1) * BLOCK).min(n)).fold(0.0, |s, i| s + f(i)))
            .fold(0.0, |a, b| a + b);
        assert_eq!(runs[0], by_hand.to_bits());
        assert_eq!(blocks(0, |r| r.len()), Vec::<usize>::new());
    }
}
