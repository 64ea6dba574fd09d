//! Timing runs that each start from a fresh scene (the build is not timed). Included by each
//! bench with `#[path]`.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// The time of `iters` runs of `run`, each on a scene fresh from `build`.
pub fn timed<S>(iters: u64, mut build: impl FnMut() -> S, mut run: impl FnMut(&mut S)) -> Duration {
    let mut total = Duration::ZERO;
    for _ in 0..iters {
        let mut sim = build();
        let start = Instant::now();
        run(&mut sim);
        total += start.elapsed();
        black_box(&sim);
    }
    total
}
