//! Helpers shared by the example games: a seeded generator, a per-step timer, and a reader of
//! the collision messages. Included by each game with `mod support;` (not an example itself:
//! the directory has no `main.rs`).
#![allow(dead_code)]

use bevy_app::App;
use bevy_ecs::message::{MessageCursor, Messages};
use bevy_ecs::prelude::*;
use std::path::Path;
use std::time::Instant;
use urto::prelude::*;

/// A small deterministic generator (the same scene on every run, no extra dependency).
pub struct Lcg(u64);

impl Lcg {
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// Uniform in `[0, 1)`.
    pub fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.next() * n as f32) as usize).min(n.saturating_sub(1))
    }
}

/// Time spent per step: the physics stages alone (from [`PhysicsStats`]) and the wall time
/// including the recording and the game's own code.
pub struct StepTimer {
    started: Instant,
    physics: f64,
    worst: f64,
    steps: u32,
}

impl StepTimer {
    pub fn start() -> Self {
        Self {
            started: Instant::now(),
            physics: 0.0,
            worst: 0.0,
            steps: 0,
        }
    }

    /// Adds the step that just ran.
    pub fn add(&mut self, app: &App) {
        let stats = app.world().resource::<PhysicsStats>();
        let t: f64 = Stage::ALL
            .iter()
            .filter(|s| **s != Stage::Debug)
            .map(|s| stats.stage_time(*s).as_secs_f64())
            .sum();
        self.physics += t;
        self.worst = self.worst.max(t);
        self.steps += 1;
    }

    /// `time per step: … µs physics (worst …), … µs with recording`.
    pub fn summary(&self) -> String {
        let n = f64::from(self.steps.max(1));
        format!(
            "time per step: {:.0} µs physics (worst step {:.0} µs), {:.0} µs with recording and game code",
            self.physics / n * 1e6,
            self.worst * 1e6,
            self.started.elapsed().as_secs_f64() / n * 1e6
        )
    }
}

/// Reads the collisions that started since the last call.
pub struct Collisions(MessageCursor<CollisionStarted>);

impl Collisions {
    pub fn new(app: &App) -> Self {
        Self(
            app.world()
                .resource::<Messages<CollisionStarted>>()
                .get_cursor(),
        )
    }

    /// The pairs that started touching in the step just run.
    pub fn read(&mut self, app: &App) -> Vec<(Entity, Entity)> {
        let messages = app.world().resource::<Messages<CollisionStarted>>();
        self.0.read(messages).map(|c| (c.a, c.b)).collect()
    }
}

/// The last line every game prints.
pub fn print_recording(path: &Path) {
    println!(
        "  recording: {}  (open it with `rerun {}`)",
        path.display(),
        path.display()
    );
}
