//! Moving bodies among static scenery: the uniform grid of the slides ("CD e CR tra un oggetto
//! e la scena statica") against putting the statics into the sweep and prune with the moving
//! bodies, and against a brute-force scan of every static object.
//!
//! The scene is town-like: buildings on a 2D lattice (random footprints and heights, z up as in
//! the slides), small props scattered in the streets, and one ground slab under everything (it
//! goes to the grid's oversize list). Bodies are unit boxes wandering through the town, bouncing
//! off its bounds; one benchmark iteration is one simulation step: move every body, then ask
//! which statics its AABB touches.
//!
//! Sizes (comma-separated lists) come from the environment:
//! - `URTO_BENCH_STATICS`  static objects per scene   (default `10000,100000`)
//! - `URTO_BENCH_BODIES`   moving bodies              (default `1,10,100,1000`)
//! - `URTO_BENCH_BRUTE_MAX_TESTS` brute force runs only where bodies × statics is at most this
//!   (default `10000000`, about 10 ms a step), so it never dominates the run.
//!
//! Quick run: `URTO_BENCH_STATICS=10000 URTO_BENCH_BODIES=1,100 cargo bench --bench static_scene
//! -- --quick`.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use std::hint::black_box;
use urto::bounding::Aabb;
use urto::broad_phase::grid::{GridQueryStats, StaticGrid};
use urto::broad_phase::{BodyKind, BroadPhase, IncrementalSap};

/// Distance between lattice points (street width plus the largest footprint).
const LATTICE_SPACING: f32 = 12.0;
/// Fraction of the statics that are buildings on the lattice; the rest are scattered props.
const BUILDING_FRACTION: f64 = 0.9;
/// Simulation step.
const DT: f32 = 1.0 / 60.0;
/// Half extent of a moving body (a unit box).
const BODY_HALF_EXTENT: f32 = 0.5;
/// Bodies fly between the ground and this height.
const SKY: f32 = 40.0;

/// SplitMix64 (Steele et al. 2014): a seeded, dependency-free generator so every run sees the
/// same town and the same motion.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`.
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        let unit = (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32;
        lo + (hi - lo) * unit
    }
}

/// The static scenery and the region the bodies wander in.
struct Town {
    statics: Vec<(u32, Aabb)>,
    bounds: Aabb,
}

impl Town {
    /// `count` statics: buildings on a square lattice, props scattered, one ground slab.
    fn generate(count: usize, seed: u64) -> Self {
        let mut rng = SplitMix64(seed);
        let buildings = ((count as f64 * BUILDING_FRACTION) as usize).max(1);
        let side = (buildings as f64).sqrt().ceil() as usize;
        let extent = side as f32 * LATTICE_SPACING;
        let bounds = Aabb::new(Vec3::ZERO, Vec3::new(extent, extent, SKY));
        let mut statics = Vec::with_capacity(count);
        let ground = Aabb::new(Vec3::new(0.0, 0.0, -1.0), Vec3::new(extent, extent, 0.0));
        statics.push(ground);
        for i in 0..buildings.min(count.saturating_sub(1)) {
            let cell = Vec3::new((i % side) as f32, (i / side) as f32, 0.0) * LATTICE_SPACING;
            let footprint = Vec3::new(rng.range(3.0, 10.0), rng.range(3.0, 10.0), 0.0);
            let slack = Vec3::splat(LATTICE_SPACING) - footprint;
            let min = cell + Vec3::new(rng.range(0.0, slack.x), rng.range(0.0, slack.y), 0.0);
            let height = rng.range(3.0, 30.0);
            statics.push(Aabb::new(
                min,
                min + footprint + Vec3::new(0.0, 0.0, height),
            ));
        }
        while statics.len() < count {
            let min = Vec3::new(
                rng.range(0.0, extent),
                rng.range(0.0, extent),
                rng.range(0.0, 3.0),
            );
            let size = Vec3::new(
                rng.range(0.2, 2.0),
                rng.range(0.2, 2.0),
                rng.range(0.2, 2.0),
            );
            statics.push(Aabb::new(min, min + size));
        }
        let statics = statics
            .into_iter()
            .enumerate()
            .map(|(i, aabb)| (i as u32, aabb))
            .collect();
        Self { statics, bounds }
    }
}

/// Unit boxes wandering through the town.
#[derive(Clone)]
struct Bodies {
    centers: Vec<Vec3>,
    velocities: Vec<Vec3>,
}

impl Bodies {
    fn spawn(count: usize, bounds: &Aabb, seed: u64) -> Self {
        let mut rng = SplitMix64(seed);
        let centers = (0..count)
            .map(|_| {
                Vec3::new(
                    rng.range(bounds.min.x, bounds.max.x),
                    rng.range(bounds.min.y, bounds.max.y),
                    rng.range(BODY_HALF_EXTENT, 20.0),
                )
            })
            .collect();
        let velocities = (0..count)
            .map(|_| {
                Vec3::new(
                    rng.range(-10.0, 10.0),
                    rng.range(-10.0, 10.0),
                    rng.range(-1.0, 1.0),
                )
            })
            .collect();
        Self {
            centers,
            velocities,
        }
    }

    /// Explicit Euler, bouncing off the town's bounds.
    fn advance(&mut self, bounds: &Aabb) {
        let lo = bounds.min + Vec3::splat(BODY_HALF_EXTENT);
        let hi = bounds.max - Vec3::splat(BODY_HALF_EXTENT);
        for (c, v) in self.centers.iter_mut().zip(&mut self.velocities) {
            *c += *v * DT;
            let outside = c.cmplt(lo) | c.cmpgt(hi);
            *v = Vec3::select(outside, -*v, *v);
            *c = c.clamp(lo, hi);
        }
    }

    fn aabb(center: Vec3) -> Aabb {
        Aabb::from_center_half_extents(center, Vec3::splat(BODY_HALF_EXTENT))
    }
}

/// One step with the grid: move, then query every body. Returns the number of hits.
fn grid_step(
    grid: &mut StaticGrid,
    bodies: &mut Bodies,
    bounds: &Aabb,
    hits: &mut Vec<u32>,
) -> usize {
    bodies.advance(bounds);
    let mut total = 0;
    for &center in &bodies.centers {
        // The query box is finite by construction; an error would be a bench bug.
        grid.query(&Bodies::aabb(center), hits)
            .expect("finite query box");
        total += hits.len();
    }
    total
}

/// One step by brute force: move, then test every body against every static.
fn brute_force_step(
    statics: &[(u32, Aabb)],
    bodies: &mut Bodies,
    bounds: &Aabb,
    hits: &mut Vec<u32>,
) -> usize {
    bodies.advance(bounds);
    let mut total = 0;
    for &center in &bodies.centers {
        let query = Bodies::aabb(center);
        hits.clear();
        hits.extend(
            statics
                .iter()
                .filter(|(_, aabb)| aabb.intersects(&query))
                .map(|&(id, _)| id),
        );
        total += hits.len();
    }
    total
}

/// The third contender: the statics inserted into the sweep and prune with the moving bodies
/// (marked static, so static–static pairs are never reported), ids `0..statics` then the bodies.
fn sap_with_statics(statics: &[(u32, Aabb)], bodies: &Bodies) -> IncrementalSap {
    let first_body = statics.len() as u32;
    let all: Vec<(u32, Aabb, BodyKind)> = statics
        .iter()
        .map(|&(id, aabb)| (id, aabb, BodyKind::Static))
        .chain(
            bodies
                .centers
                .iter()
                .enumerate()
                .map(|(i, &c)| (first_body + i as u32, Bodies::aabb(c), BodyKind::Dynamic)),
        )
        .collect();
    let mut sap = IncrementalSap::new();
    sap.insert_bulk(&all).expect("the town's boxes are valid");
    sap.commit();
    sap
}

/// One step with the statics in the sweep and prune: move, update every body, commit (the
/// bodies' endpoints now also pass the statics' endpoints). Returns the number of pairs.
fn sap_step(
    sap: &mut IncrementalSap,
    first_body: u32,
    bodies: &mut Bodies,
    bounds: &Aabb,
) -> usize {
    bodies.advance(bounds);
    for (i, &c) in bodies.centers.iter().enumerate() {
        // Every body was inserted at build time; an error would be a bench bug.
        sap.update(first_body + i as u32, Bodies::aabb(c))
            .expect("known body");
    }
    sap.commit();
    sap.pairs().len()
}

/// A comma-separated list of sizes from the environment, or the default.
fn sizes_from_env(name: &str, default: &[usize]) -> Vec<usize> {
    match std::env::var(name) {
        Ok(list) => list
            .split(',')
            .filter_map(|s| s.trim().parse().ok())
            .collect(),
        Err(_) => default.to_vec(),
    }
}

/// Prints, once per scene, what the grid looks like and what an average query costs, so the
/// timings can be read against the counters; checks the grid's hits against brute force.
fn describe(grid: &mut StaticGrid, town: &Town, bodies: &Bodies) {
    let mut stats = GridQueryStats::default();
    let mut hits = Vec::new();
    let mut found = 0;
    for &center in &bodies.centers {
        stats += grid
            .query(&Bodies::aabb(center), &mut hits)
            .expect("finite query box");
        found += hits.len();
    }
    let brute: usize = bodies
        .centers
        .iter()
        .map(|&c| {
            let query = Bodies::aabb(c);
            town.statics
                .iter()
                .filter(|(_, aabb)| aabb.intersects(&query))
                .count()
        })
        .sum();
    assert_eq!(
        found, brute,
        "the grid and brute force disagree on the bench scene"
    );
    let n = bodies.centers.len().max(1) as f64;
    eprintln!(
        "statics {}: cell {:?}, {} occupied cells, {} oversize, {:.1} MiB; per query: {:.1} cells, {:.1} listed, {:.1} exact tests, {:.2} hits",
        town.statics.len(),
        grid.cell_size(),
        grid.occupied_cell_count(),
        grid.oversize_count(),
        grid.memory_bytes() as f64 / (1024.0 * 1024.0),
        stats.cells_visited as f64 / n,
        stats.candidates_listed as f64 / n,
        stats.exact_tests as f64 / n,
        found as f64 / n,
    );
}

fn bench_static_scene(c: &mut Criterion) {
    let statics_sizes = sizes_from_env("URTO_BENCH_STATICS", &[10_000, 100_000]);
    let body_counts = sizes_from_env("URTO_BENCH_BODIES", &[1, 10, 100, 1000]);
    let brute_max_tests = sizes_from_env("URTO_BENCH_BRUTE_MAX_TESTS", &[10_000_000])
        .first()
        .copied()
        .unwrap_or(10_000_000);

    for &statics in &statics_sizes {
        let town = Town::generate(statics, 0x5EED_0000 + statics as u64);

        let mut build = c.benchmark_group(format!("static_scene_build/{statics}"));
        build.throughput(Throughput::Elements(statics as u64));
        build.bench_function("grid", |b| {
            b.iter(|| StaticGrid::build(black_box(&town.statics)).expect("valid town"))
        });
        build.finish();

        let mut grid = StaticGrid::build(&town.statics).expect("the town's boxes are valid");
        describe(&mut grid, &town, &Bodies::spawn(1000, &town.bounds, 7));

        let mut group = c.benchmark_group(format!("static_scene_step/{statics}"));
        for &bodies in &body_counts {
            group.throughput(Throughput::Elements(bodies as u64));
            let start = Bodies::spawn(bodies, &town.bounds, 0xB0D1E5 + bodies as u64);

            let mut moving = start.clone();
            let mut hits = Vec::new();
            group.bench_function(BenchmarkId::new("grid", bodies), |b| {
                b.iter(|| grid_step(&mut grid, &mut moving, &town.bounds, &mut hits))
            });

            if bodies.saturating_mul(statics) <= brute_max_tests {
                let mut moving = start.clone();
                group.bench_function(BenchmarkId::new("brute_force", bodies), |b| {
                    b.iter(|| brute_force_step(&town.statics, &mut moving, &town.bounds, &mut hits))
                });
            }

            let mut moving = start.clone();
            let mut sap = sap_with_statics(&town.statics, &moving);
            group.bench_function(BenchmarkId::new("sap", bodies), |b| {
                b.iter(|| {
                    sap_step(
                        &mut sap,
                        town.statics.len() as u32,
                        &mut moving,
                        &town.bounds,
                    )
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench_static_scene);
criterion_main!(benches);
