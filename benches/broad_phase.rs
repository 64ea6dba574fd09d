//! Broad-phase benchmarks: incremental sweep and prune (both pair-tracking strategies) against
//! sort-and-sweep from scratch and brute force, time per step (updates + commit).
//!
//! Scenes: boxes with sides uniform in 0.5..1.5 in a cube of side `(8n/3)^(1/3)`, so each body
//! overlaps about 3 others.
//! - `game-like`: each step 10% of the bodies (picked at random) jitter by up to 0.05 per axis,
//!   the rest are at rest;
//! - `dense-cloud`: every body moves 0.05 per step along its own direction, bouncing off the
//!   walls; `cloud-speed` repeats it at one size for speeds 0.01, 0.05, 0.2, 1.0 to show where
//!   re-sorting from scratch overtakes the incremental sort;
//! - `build`: bulk insert of the whole scene and the first commit.
//!
//! Environment: `URTO_BENCH_SIZES` (default `1000,10000,100000`) lists the body counts;
//! `URTO_BENCH_SWEEP_N` the size of the speed sweep (default 10000, or the largest listed size
//! if smaller). Brute force and the axis-bits table run only up to 10k bodies (quadratic time,
//! and memory). After each benchmark a `[summary]` line on stderr gives swaps and pair tests
//! per step, pairs, and heap bytes per body.

use criterion::{BenchmarkId, Criterion, SamplingMode, criterion_group, criterion_main};
use glam::Vec3;
use std::hint::black_box;
use std::time::Duration;
use urto::bounding::Aabb;
use urto::broad_phase::{
    AxisBits, AxisTests, BodyKind, BroadPhase, BruteForce, IncrementalSap, PairTracking, ProxyId,
    SortAndSweep,
};

/// Largest size at which the quadratic or table-heavy variants run.
const SMALL_ONLY: usize = 10_000;

/// xorshift64*: a tiny deterministic generator, so every run sees the same scenes.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32 / (1u64 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    fn index(&mut self, n: usize) -> usize {
        ((self.unit() * n as f32) as usize).min(n - 1)
    }

    fn direction(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let len = v.length();
            if len > 0.1 && len <= 1.0 {
                return v / len;
            }
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Motion {
    /// 10% of the bodies jitter by up to this much per axis.
    GameLike(f32),
    /// All bodies move this far per step.
    Cloud(f32),
}

/// Bodies in a cube, and their motion.
struct Scene {
    side: f32,
    centers: Vec<Vec3>,
    halves: Vec<Vec3>,
    directions: Vec<Vec3>,
    rng: Rng,
}

impl Scene {
    fn new(n: usize) -> Self {
        let side = (8.0 * n as f32 / 3.0).cbrt();
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ n as u64);
        let centers = (0..n)
            .map(|_| {
                Vec3::new(
                    rng.range(0.0, side),
                    rng.range(0.0, side),
                    rng.range(0.0, side),
                )
            })
            .collect();
        let halves = (0..n)
            .map(|_| {
                Vec3::new(
                    rng.range(0.25, 0.75),
                    rng.range(0.25, 0.75),
                    rng.range(0.25, 0.75),
                )
            })
            .collect();
        let directions = (0..n).map(|_| rng.direction()).collect();
        Self {
            side,
            centers,
            halves,
            directions,
            rng,
        }
    }

    fn aabb(&self, i: usize) -> Aabb {
        Aabb::from_center_half_extents(self.centers[i], self.halves[i])
    }

    fn bodies(&self) -> Vec<(ProxyId, Aabb, BodyKind)> {
        (0..self.centers.len())
            .map(|i| (i as ProxyId, self.aabb(i), BodyKind::Dynamic))
            .collect()
    }

    /// Moves the bodies one step and tells the broad phase (without committing).
    fn step(&mut self, motion: Motion, bp: &mut impl BroadPhase) {
        let n = self.centers.len();
        match motion {
            Motion::GameLike(jitter) => {
                for _ in 0..n / 10 {
                    let i = self.rng.index(n);
                    let d = Vec3::new(
                        self.rng.range(-jitter, jitter),
                        self.rng.range(-jitter, jitter),
                        self.rng.range(-jitter, jitter),
                    );
                    self.centers[i] =
                        (self.centers[i] + d).clamp(Vec3::ZERO, Vec3::splat(self.side));
                    bp.update(i as ProxyId, self.aabb(i))
                        .expect("scene boxes are valid");
                }
            }
            Motion::Cloud(speed) => {
                for i in 0..n {
                    let mut c = self.centers[i] + self.directions[i] * speed;
                    for axis in 0..3 {
                        if c[axis] < 0.0 || c[axis] > self.side {
                            self.directions[i][axis] = -self.directions[i][axis];
                            c[axis] = c[axis].clamp(0.0, self.side);
                        }
                    }
                    self.centers[i] = c;
                    bp.update(i as ProxyId, self.aabb(i))
                        .expect("scene boxes are valid");
                }
            }
        }
    }
}

/// A scene and a broad phase holding it, committed once.
fn prepared<B: BroadPhase + Default>(n: usize) -> (Scene, B) {
    let scene = Scene::new(n);
    let mut bp = B::default();
    bp.insert_bulk(&scene.bodies())
        .expect("scene boxes are valid");
    bp.commit();
    (scene, bp)
}

/// Times one step of `motion` for broad phase `B`, then prints its summary line.
fn bench_steps<B: BroadPhase + Default>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    label: &str,
    n: usize,
    motion: Motion,
) {
    let (mut scene, mut bp) = prepared::<B>(n);
    group.bench_function(BenchmarkId::new(name, label), |b| {
        b.iter(|| {
            scene.step(motion, &mut bp);
            bp.commit();
            black_box(bp.pairs().len())
        })
    });
    summarize(
        group_label(motion),
        name,
        label,
        &mut scene,
        &mut bp,
        motion,
    );
}

fn group_label(motion: Motion) -> &'static str {
    match motion {
        Motion::GameLike(_) => "game-like",
        Motion::Cloud(_) => "dense-cloud",
    }
}

/// Averages the counters over a few more steps and prints them.
fn summarize<B: BroadPhase>(
    group: &str,
    name: &str,
    label: &str,
    scene: &mut Scene,
    bp: &mut B,
    motion: Motion,
) {
    const STEPS: u64 = 5;
    let (mut swaps, mut tests) = (0, 0);
    for _ in 0..STEPS {
        scene.step(motion, bp);
        bp.commit();
        swaps += bp.stats().endpoint_swaps;
        tests += bp.stats().pair_tests;
    }
    eprintln!(
        "[summary] {group} {label} {name}: swaps/step {} pair-tests/step {} pairs {} bytes/body {:.0}",
        swaps / STEPS,
        tests / STEPS,
        bp.pairs().len(),
        bp.memory_bytes() as f64 / bp.len().max(1) as f64,
    );
}

fn env_sizes() -> Vec<usize> {
    std::env::var("URTO_BENCH_SIZES")
        .ok()
        .map(|s| {
            s.split(',')
                .filter_map(|x| x.trim().parse().ok())
                .collect::<Vec<usize>>()
        })
        .filter(|sizes| !sizes.is_empty())
        .unwrap_or_else(|| vec![1_000, 10_000, 100_000])
}

fn sweep_size(sizes: &[usize]) -> usize {
    std::env::var("URTO_BENCH_SWEEP_N")
        .ok()
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or_else(|| {
            sizes
                .iter()
                .copied()
                .max()
                .unwrap_or(SMALL_ONLY)
                .min(SMALL_ONLY)
        })
}

fn sap_name<T: PairTracking>() -> String {
    format!("sap-{}", T::NAME)
}

/// Every broad phase on one motion at one size.
fn bench_all(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    n: usize,
    motion: Motion,
) {
    let label = format!("n={n}");
    bench_steps::<IncrementalSap<AxisTests>>(group, &sap_name::<AxisTests>(), &label, n, motion);
    if n <= SMALL_ONLY {
        bench_steps::<IncrementalSap<AxisBits>>(group, &sap_name::<AxisBits>(), &label, n, motion);
    }
    bench_steps::<SortAndSweep>(group, "sort-sweep", &label, n, motion);
    if n <= SMALL_ONLY {
        bench_steps::<BruteForce>(group, "brute-force", &label, n, motion);
    }
}

fn configure(group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_millis(500));
}

fn broad_phase(c: &mut Criterion) {
    let sizes = env_sizes();
    for (motion, name) in [
        (Motion::GameLike(0.05), "game-like"),
        (Motion::Cloud(0.05), "dense-cloud"),
    ] {
        let mut group = c.benchmark_group(name);
        configure(&mut group);
        for &n in &sizes {
            bench_all(&mut group, n, motion);
        }
        group.finish();
    }

    let n = sweep_size(&sizes);
    let mut group = c.benchmark_group("cloud-speed");
    configure(&mut group);
    for speed in [0.01, 0.05, 0.2, 1.0] {
        let label = format!("n={n}/speed={speed}");
        let motion = Motion::Cloud(speed);
        bench_steps::<IncrementalSap<AxisTests>>(
            &mut group,
            &sap_name::<AxisTests>(),
            &label,
            n,
            motion,
        );
        bench_steps::<SortAndSweep>(&mut group, "sort-sweep", &label, n, motion);
    }
    group.finish();

    let mut group = c.benchmark_group("build");
    configure(&mut group);
    for &n in &sizes {
        let bodies = Scene::new(n).bodies();
        let label = format!("n={n}");
        group.bench_function(BenchmarkId::new(sap_name::<AxisTests>(), &label), |b| {
            b.iter(|| build::<IncrementalSap<AxisTests>>(&bodies))
        });
        group.bench_function(BenchmarkId::new("sort-sweep", &label), |b| {
            b.iter(|| build::<SortAndSweep>(&bodies))
        });
    }
    group.finish();
}

/// Bulk insert plus the first commit; returns the pair count.
fn build<B: BroadPhase + Default>(bodies: &[(ProxyId, Aabb, BodyKind)]) -> usize {
    let mut bp = B::default();
    bp.insert_bulk(bodies).expect("scene boxes are valid");
    bp.commit();
    black_box(bp.pairs().len())
}

criterion_group!(benches, broad_phase);
criterion_main!(benches);
