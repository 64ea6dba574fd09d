//! What the robot arm example measures: the scene-graph descent's work, which part of the arm
//! touched what, how the motors followed their targets, and the report printed at the end.

use crate::{Args, Arm, BENCH_TOP, TURN_RATE, pose, support};
use bevy_app::App;
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;
use glam::Vec3;
use std::collections::BTreeMap;
use std::f32::consts::TAU;
use support::StepTimer;
use urto::plugins::narrow_phase::HierarchyVisits;
use urto::plugins::{BroadPhasePairs, Contacts};
use urto::prelude::*;

/// The descent's work, summed over steps (each measured in the step's last substep, which the
/// visits and the broad-phase pairs describe).
#[derive(Default)]
pub(crate) struct Work {
    /// Broad-phase pairs involving a compound (a link of the arm or the tray).
    pub(crate) compound_pairs: u64,
    pub(crate) entered: u64,
    pub(crate) pruned: u64,
    pub(crate) collider_pairs: u64,
    /// What testing every collider of one side against every collider of the other would cost.
    pub(crate) all_pairs: u64,
    pub(crate) peak_collider_pairs: usize,
    /// Per step over all substeps, from the physics counters.
    pub(crate) bv_tests: f64,
    pub(crate) steps: u64,
}

impl Work {
    pub(crate) fn add(&mut self, app: &App, colliders: &BTreeMap<Entity, u64>) {
        let world = app.world();
        let visits = world.resource::<HierarchyVisits>();
        let count = |e: &Entity| colliders.get(e).copied();
        for (a, b) in &world.resource::<BroadPhasePairs>().pairs {
            if count(a).is_some() || count(b).is_some() {
                self.compound_pairs += 1;
                self.all_pairs += count(a).unwrap_or(1) * count(b).unwrap_or(1);
            }
        }
        self.entered += visits.entered.len() as u64;
        self.pruned += visits.pruned.len() as u64;
        self.collider_pairs += visits.collider_pairs.len() as u64;
        self.peak_collider_pairs = self.peak_collider_pairs.max(visits.collider_pairs.len());
        let stats = world.resource::<PhysicsStats>();
        self.bv_tests += stats.counter("hierarchy/bv_tests").unwrap_or(0.0);
        self.steps += 1;
    }

    pub(crate) fn per_step(&self, total: u64) -> f64 {
        total as f64 / self.steps.max(1) as f64
    }
}

/// The part of the arm that first touched each body, noted in every substep (a graze can
/// begin and end within one step).
#[derive(Resource)]
pub(crate) struct FirstTouches {
    pub(crate) links: Vec<Entity>,
    pub(crate) parts: BTreeMap<Entity, Entity>,
}

/// Notes, from this substep's contacts, which part of the arm touched what (game code in the
/// substep schedule, after the narrow phase).
pub(crate) fn note_touches(contacts: Res<Contacts>, mut touches: ResMut<FirstTouches>) {
    for c in &contacts.pairs {
        let (other, part) = match (c.a, c.b) {
            (a, b) if touches.links.contains(&a) => (b, c.collider_a),
            (a, b) if touches.links.contains(&b) => (a, c.collider_b),
            _ => continue,
        };
        if !touches.links.contains(&other) {
            touches.parts.entry(other).or_insert(part);
        }
    }
}

/// How the motors followed their targets.
#[derive(Default)]
pub(crate) struct Tracking {
    /// The turret's turn so far (rad, unwrapped) and its last yaw.
    pub(crate) turned: f32,
    pub(crate) last_yaw: f32,
    /// The turret's speed summed after its first second, and the number of samples.
    pub(crate) speed_sum: f32,
    pub(crate) speed_samples: u32,
    /// Per pitch joint (shoulder, elbow, wrist): worst and summed squared lag behind the target
    /// (rad), and the largest torque its motor applied (N·m).
    pub(crate) worst_lag: [f32; 3],
    pub(crate) lag_squares: [f64; 3],
    pub(crate) peak_torque: [f32; 3],
    pub(crate) samples: u32,
    /// The widest gap between a joint's two anchors (m) and the furthest past a limit (rad).
    pub(crate) worst_gap: f32,
    pub(crate) worst_past_limit: f32,
}

/// What happened during the run.
pub(crate) struct Report {
    /// Times an obstacle started touching the arm.
    pub(crate) hits: u32,
    /// Where the obstacles started.
    pub(crate) starts: Vec<Vec3>,
    pub(crate) tracking: Tracking,
    pub(crate) work: Work,
    pub(crate) timer: StepTimer,
}

impl Tracking {
    /// Notes how far each pitch joint is from its target, what its motor applied, the joints'
    /// gaps and limits, and (once `settled`, after the first second) the turret's speed.
    pub(crate) fn add(&mut self, app: &App, arm: &Arm, targets: [f32; 3], settled: bool) {
        let world = app.world();
        for (i, &e) in arm.joints.iter().enumerate() {
            let Some(joint) = world.get::<Joint>(e) else {
                continue;
            };
            let b = joint.body_b_entity().map(|b| pose(app, b));
            let (a, b) = joint.world_frames(pose(app, joint.body_a), b);
            self.worst_gap = self.worst_gap.max(a.translation.distance(b.translation));
            self.worst_past_limit = self.worst_past_limit.max(joint.past_limit(&a, &b));
            let Some(k) = i.checked_sub(1) else {
                continue;
            };
            let lag = (joint.coordinate(&a, &b) - targets[k]).abs();
            self.worst_lag[k] = self.worst_lag[k].max(lag);
            self.lag_squares[k] += f64::from(lag * lag);
            let torque = world.get::<JointLoad>(e).map_or(0.0, |l| l.motor.abs());
            self.peak_torque[k] = self.peak_torque[k].max(torque);
        }
        self.samples += 1;
        if settled {
            let spin = world.get::<AngularVelocity>(arm.links[0]);
            self.speed_sum += spin.map_or(0.0, |w| w.0.z);
            self.speed_samples += 1;
        }
    }

    pub(crate) fn rms_lag(&self, k: usize) -> f32 {
        (self.lag_squares[k] / f64::from(self.samples.max(1))).sqrt() as f32
    }
}

impl Report {
    pub(crate) fn print(&self, app: &App, args: &Args, arm: &Arm, obstacles: &[Entity]) {
        let world = app.world();
        let stats = world.resource::<PhysicsStats>();
        let t = &self.tracking;
        println!(
            "robot_arm: an arm of 4 motor-driven links ({} colliders) clearing a bench of {} obstacles (crates, balls, a tray of 3 bottles); {} steps ({:.0} s simulated, {:.1} turns)",
            arm.colliders.iter().sum::<usize>(),
            obstacles.len(),
            stats.step,
            stats.sim_time,
            t.turned / TAU
        );
        let ends: Vec<Vec3> = obstacles
            .iter()
            .map(|&e| pose(app, e).translation)
            .collect();
        let off = ends.iter().filter(|p| p.z < BENCH_TOP - 0.05).count();
        let moved = ends.iter().zip(&self.starts);
        let pushed = moved
            .filter(|(p, s)| p.z >= BENCH_TOP - 0.05 && p.distance(**s) > 0.1)
            .count();
        let parts = &world.resource::<FirstTouches>().parts;
        let (touched, scenery): (Vec<_>, Vec<_>) =
            parts.iter().partition(|(o, _)| obstacles.contains(o));
        let mut by_part: BTreeMap<&str, u32> = BTreeMap::new();
        for &(_, &part) in &touched {
            let name = world.get::<Name>(part).map_or("?", |n| n.as_str());
            *by_part.entry(name).or_default() += 1;
        }
        let by_part: Vec<String> = by_part.iter().map(|(l, n)| format!("{l} {n}")).collect();
        println!(
            "  the arm touched {} of {} obstacles ({} hits; first touched by: {}); {off} knocked off the bench, {pushed} pushed along it, {} left in place; it touched {} pieces of bench or floor",
            touched.len(),
            obstacles.len(),
            self.hits,
            by_part.join(", "),
            obstacles.len() - off - pushed,
            scenery.len(),
        );
        let lags: Vec<String> = ["shoulder", "elbow", "wrist"]
            .iter()
            .enumerate()
            .map(|(k, name)| {
                format!(
                    "{name} {:.1}° rms, {:.1}° worst, {:.0} N·m peak",
                    t.rms_lag(k).to_degrees(),
                    t.worst_lag[k].to_degrees(),
                    t.peak_torque[k]
                )
            })
            .collect();
        println!(
            "  motors: the turret turned at {:.3} rad/s (target {TURN_RATE:.3}); behind their targets: {}; joints at most {:.1} mm apart and {:.1}° past a limit",
            t.speed_sum / t.speed_samples.max(1) as f32,
            lags.join("; "),
            t.worst_gap * 1e3,
            t.worst_past_limit.to_degrees(),
        );
        let w = &self.work;
        println!(
            "  scene-graph descent, per step (its last substep): {:.1} broad-phase pairs with a compound; entered {:.1} nodes, pruned {:.1}, {:.2} collider pairs to the exact test (peak {}) instead of {:.1} for every collider against every collider; {:.1} volume tests per step (all substeps)",
            w.per_step(w.compound_pairs),
            w.per_step(w.entered),
            w.per_step(w.pruned),
            w.per_step(w.collider_pairs),
            w.peak_collider_pairs,
            w.per_step(w.all_pairs),
            w.bv_tests / w.steps.max(1) as f64,
        );
        println!("  {}", self.timer.summary());
        support::print_recording(&args.recording.path("robot_arm"));
    }
}
