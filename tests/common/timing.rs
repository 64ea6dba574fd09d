//! Wall-clock timing for the measuring examples and benches: the mean of repeated calls, long
//! enough that the clock's resolution and one-off effects (a cold cache, a page fault) fade.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// Mean time of one call of `f`, after one warm-up call, over at least `min_time` and 3 calls.
pub fn mean_time<R>(min_time: Duration, mut f: impl FnMut() -> R) -> Duration {
    black_box(f());
    let start = Instant::now();
    let mut calls = 0u32;
    while start.elapsed() < min_time || calls < 3 {
        black_box(f());
        calls += 1;
    }
    start.elapsed() / calls
}

/// The smallest of `repeats` means, each [`mean_time`] over `min_time / repeats`: other processes
/// only ever add time, so on a shared machine the minimum is the best estimate of the work's own
/// cost.
pub fn min_of_means<R>(repeats: u32, min_time: Duration, mut f: impl FnMut() -> R) -> Duration {
    let repeats = repeats.max(1);
    (0..repeats)
        .map(|_| mean_time(min_time / repeats, &mut f))
        .min()
        .unwrap_or_default()
}
