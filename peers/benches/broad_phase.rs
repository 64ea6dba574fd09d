//! Broad-phase peer benchmark (issue 12): urto's incremental sweep and prune, its adaptive
//! variant (which falls back to sorting from scratch while insertion sort loses) and its
//! segmented one (`RegionSweep`: a sweep per cell of a self-tuned grid), against
//! parry3d's `Bvh` (the tree rapier3d's broad phase is built on) on the same scenes, in one
//! process.
//!
//! Scenes of unit boxes (about two overlaps each unless said): a cloud of 1k, 10k and 100k
//! boxes all moving 0.05 m a step in random directions (bouncing inside the cloud's cube); 100k
//! with 1 % moving; a row of 10k along x, each box overlapping its two neighbours, all
//! jittering (SAP's worst case: every endpoint on y and z passes hundreds of others); 10k of
//! mixed sizes (half extents 0.1–2 m).
//!
//! The same work each step: each moved box's new AABB handed over, and the full list of
//! overlapping pairs out. urto: `update` per moved body, `commit`, `pairs()` (kept
//! incrementally). parry3d 0.31: `insert_or_update_partially` per moved leaf, `refit`,
//! `optimize_incremental`, and a full self-traversal (`traverse_bvtt_single_tree::<false>`)
//! collecting every overlapping leaf pair (rapier adds change detection and its own pair map on
//! top; not measured here). Quality check printed per scene: both pair counts after the last
//! step (they must agree: both are exact AABB overlaps). Each engine steps `STEPS` times after
//! `WARM_UP` steps, interleaved step by step so both see the same machine load; the time is the
//! median step. Single thread.
//!
//! Run (from `peers/`): `cargo bench --bench broad_phase`; `PEERS_BROAD_PHASE_QUICK=1` drops the
//! 100k scenes, `PEERS_BROAD_PHASE_1M=1` adds a cloud of 1M all moving (a few minutes: the
//! whole-scene SAP takes seconds a step there).

use glam::Vec3;
use rapier3d::parry::bounding_volume::Aabb as ParryAabb;
use rapier3d::parry::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};
use std::time::{Duration, Instant};
use urto::bounding::Aabb;
use urto::broad_phase::{AdaptiveSweep, BodyKind, BroadPhase, IncrementalSap, RegionSweep};

const WARM_UP: usize = 5;
const STEPS: usize = 30;

/// The tests' seeded generator (SplitMix64): the same boxes and motion for both engines, every
/// run.
#[allow(dead_code)]
#[path = "common/rapier_world.rs"]
mod rapier_world;
use rapier_world::rv;

#[allow(dead_code)]
#[path = "../../tests/common/rng.rs"]
mod rng;
use rng::Rng;

/// `n` points uniformly in the cube `[0, side]³`.
fn in_cube(n: usize, side: f32, rng: &mut Rng) -> Vec<Vec3> {
    (0..n)
        .map(|_| {
            Vec3::new(
                rng.range(0.0, side),
                rng.range(0.0, side),
                rng.range(0.0, side),
            )
        })
        .collect()
}

/// A scene: box centres, half extents, which boxes move and how, inside `bounds`.
struct Scene {
    name: String,
    centers: Vec<Vec3>,
    halves: Vec<Vec3>,
    velocities: Vec<Vec3>,
    moving: Vec<u32>,
    bounds: (Vec3, Vec3),
}

impl Scene {
    /// `n` unit boxes in a cube sized for about two overlaps each, `moving` of them moving.
    fn cloud(n: usize, moving_fraction: f32, seed: u64) -> Self {
        let side = (4.0 * n as f32).cbrt();
        let mut rng = Rng::new(seed);
        let centers = in_cube(n, side, &mut rng);
        let name = if moving_fraction < 1.0 {
            format!("cloud {n}, {:.0} % moving", moving_fraction * 100.0)
        } else {
            format!("cloud {n}, all moving")
        };
        Self::finish(
            name,
            centers,
            vec![Vec3::splat(0.5); n],
            moving_fraction,
            0.05,
            &mut rng,
        )
    }

    /// `n` unit boxes along x, 0.9 m apart (each overlaps its two neighbours), jittering.
    fn row(n: usize, seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        let centers = (0..n)
            .map(|i| Vec3::new(i as f32 * 0.9, rng.range(0.0, 0.1), rng.range(0.0, 0.1)))
            .collect();
        let name = format!("row of {n} along x, all moving");
        Self::finish(
            name,
            centers,
            vec![Vec3::splat(0.5); n],
            1.0,
            0.01,
            &mut rng,
        )
    }

    /// `n` boxes of half extents 0.1–2 m, all moving.
    fn mixed(n: usize, seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        let halves: Vec<Vec3> = (0..n)
            .map(|_| {
                Vec3::new(
                    rng.range(0.1, 2.0),
                    rng.range(0.1, 2.0),
                    rng.range(0.1, 2.0),
                )
            })
            .collect();
        let volume: f32 = halves.iter().map(|h| 8.0 * h.x * h.y * h.z).sum();
        let side = (2.0 * volume).cbrt();
        let centers = in_cube(n, side, &mut rng);
        Self::finish(
            format!("{n} of mixed sizes, all moving"),
            centers,
            halves,
            1.0,
            0.05,
            &mut rng,
        )
    }

    fn finish(
        name: String,
        centers: Vec<Vec3>,
        halves: Vec<Vec3>,
        moving_fraction: f32,
        speed: f32,
        rng: &mut Rng,
    ) -> Self {
        let n = centers.len();
        let (lo, hi) = centers.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &c: &Vec3| (lo.min(c), hi.max(c)),
        );
        let moving = (0..n as u32)
            .filter(|_| rng.unit() < moving_fraction)
            .collect();
        let velocities = (0..n).map(|_| rng.direction() * speed).collect();
        Self {
            name,
            centers,
            halves,
            velocities,
            moving,
            bounds: (lo, hi),
        }
    }

    /// Moves the moving boxes one step, bouncing off the scene's bounds.
    fn advance(&mut self) {
        let (lo, hi) = self.bounds;
        for &i in &self.moving {
            let i = i as usize;
            let mut c = self.centers[i] + self.velocities[i];
            let v = &mut self.velocities[i];
            for axis in 0..3 {
                if c[axis] < lo[axis] || c[axis] > hi[axis] {
                    v[axis] = -v[axis];
                    c[axis] = c[axis].clamp(lo[axis], hi[axis]);
                }
            }
            self.centers[i] = c;
        }
    }

    fn aabb(&self, i: usize) -> Aabb {
        Aabb::from_center_half_extents(self.centers[i], self.halves[i])
    }

    fn parry_aabb(&self, i: usize) -> ParryAabb {
        let (c, h) = (self.centers[i], self.halves[i]);
        let (lo, hi) = (c - h, c + h);
        ParryAabb::new(rv(lo), rv(hi))
    }
}

/// parry3d's tree with its workspace and the pair list it fills each step.
struct ParryBroadPhase {
    tree: Bvh,
    workspace: BvhWorkspace,
    pairs: Vec<(u32, u32)>,
}

impl ParryBroadPhase {
    fn new(scene: &Scene) -> Self {
        let leaves: Vec<ParryAabb> = (0..scene.centers.len())
            .map(|i| scene.parry_aabb(i))
            .collect();
        Self {
            tree: Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves),
            workspace: BvhWorkspace::default(),
            pairs: Vec::new(),
        }
    }

    fn step(&mut self, scene: &Scene) {
        for &i in &scene.moving {
            self.tree
                .insert_or_update_partially(scene.parry_aabb(i as usize), i, 0.0);
        }
        self.tree.refit(&mut self.workspace);
        self.tree.optimize_incremental(&mut self.workspace);
        self.pairs.clear();
        let pairs = &mut self.pairs;
        self.tree
            .traverse_bvtt_single_tree::<false>(&mut self.workspace, &mut |a, b| {
                pairs.push((a, b))
            });
    }
}

/// An urto broad phase holding the scene's boxes.
fn urto_filled<B: BroadPhase + Default>(scene: &Scene) -> B {
    let mut bp = B::default();
    let bodies: Vec<_> = (0..scene.centers.len())
        .map(|i| (i as u32, scene.aabb(i), BodyKind::Dynamic))
        .collect();
    bp.insert_bulk(&bodies).expect("finite boxes");
    bp.commit();
    bp
}

fn urto_step(bp: &mut impl BroadPhase, scene: &Scene) -> usize {
    for &i in &scene.moving {
        bp.update(i, scene.aabb(i as usize)).expect("a known box");
    }
    bp.commit();
    bp.pairs().len()
}

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort_unstable();
    times[times.len() / 2]
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// `a` against `b` as "urto … faster/slower".
fn ratio(urto: Duration, peer: Duration) -> String {
    if urto <= peer {
        format!("{:.2}× faster", ms(peer) / ms(urto))
    } else {
        format!("**{:.2}× slower**", ms(urto) / ms(peer))
    }
}

/// Steps the four broad phases on `scene`, interleaved, and prints its table row.
fn run(mut scene: Scene) {
    let mut sap: IncrementalSap = urto_filled(&scene);
    let mut adaptive: AdaptiveSweep = urto_filled(&scene);
    let mut regions: RegionSweep = urto_filled(&scene);
    let mut parry = ParryBroadPhase::new(&scene);
    let mut times = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    let mut pairs = [0; 3];
    for step in 0..WARM_UP + STEPS {
        scene.advance();
        let start = Instant::now();
        pairs[0] = urto_step(&mut sap, &scene);
        let t0 = start.elapsed();
        let start = Instant::now();
        pairs[1] = urto_step(&mut adaptive, &scene);
        let t1 = start.elapsed();
        let start = Instant::now();
        pairs[2] = urto_step(&mut regions, &scene);
        let t2 = start.elapsed();
        let start = Instant::now();
        parry.step(&scene);
        let t3 = start.elapsed();
        if step >= WARM_UP {
            for (list, t) in times.iter_mut().zip([t0, t1, t2, t3]) {
                list.push(t);
            }
        }
    }
    let [s, a, r, p] = times.map(median);
    let [sap_pairs, adaptive_pairs, region_pairs] = pairs;
    println!(
        "| {} | {:.3} ms | {:.3} ms ({}) | {:.3} ms ({:.2} m cells, {:.0} per region) | {:.3} ms | SAP {}, adaptive {}, regions {} | {sap_pairs} / {adaptive_pairs} / {region_pairs} / {} |",
        scene.name,
        ms(s),
        ms(a),
        if adaptive.is_sorting_from_scratch() {
            "sorting from scratch"
        } else if adaptive.is_in_regions() {
            "regions"
        } else {
            "incremental"
        },
        ms(r),
        regions.cell_size().unwrap_or(0.0),
        regions.members_per_region(),
        ms(p),
        ratio(s, p),
        ratio(a, p),
        ratio(r, p),
        parry.pairs.len()
    );
}

fn main() {
    let quick = std::env::var("PEERS_BROAD_PHASE_QUICK").is_ok();
    println!(
        "| scene | urto SAP | urto adaptive (mode at the end) | urto regions (layout at the end) | parry3d Bvh | urto vs parry | pairs (SAP / adaptive / regions / parry) |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | --- | ---: |");
    run(Scene::cloud(1_000, 1.0, 1));
    run(Scene::cloud(10_000, 1.0, 2));
    if !quick {
        run(Scene::cloud(100_000, 1.0, 3));
        run(Scene::cloud(100_000, 0.01, 4));
    }
    run(Scene::row(10_000, 5));
    run(Scene::mixed(10_000, 6));
    if std::env::var("PEERS_BROAD_PHASE_1M").is_ok() {
        run(Scene::cloud(1_000_000, 1.0, 7));
    }
}
