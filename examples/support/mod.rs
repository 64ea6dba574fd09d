//! Helpers shared by the example games: their app and recording options, a seeded generator, a
//! per-step timer, and a reader of the collision messages. Included by each game with `mod support;` (not an example itself:
//! the directory has no `main.rs`).
#![allow(dead_code)]

use bevy_app::{App, PluginGroupBuilder};
use bevy_ecs::message::{MessageCursor, Messages};
use bevy_ecs::prelude::*;
use std::error::Error;
use std::path::{Path, PathBuf};
use std::time::Instant;
use urto::debug::RerunConfig;
use urto::prelude::*;

/// A game's app: urto at 60 steps per second with `substeps`, gravity and contact settings.
pub fn game_app(
    substeps: u32,
    gravity: Gravity,
    contacts: ContactSettings,
) -> Result<App, Box<dyn Error>> {
    app_with(substeps, gravity, contacts, |group| group)
}

/// [`game_app`] with the lecture's pipeline (integration and impulse response in every substep)
/// in place of the rigid-body solver: for the games that show what that pipeline does.
pub fn lecture_game_app(
    substeps: u32,
    gravity: Gravity,
    contacts: ContactSettings,
) -> Result<App, Box<dyn Error>> {
    app_with(substeps, gravity, contacts, |group| {
        group.disable::<SoftStepPlugin>()
    })
}

/// The app of [`game_app`] with `UrtoPlugins` changed by `choose` before it is added.
fn app_with(
    substeps: u32,
    gravity: Gravity,
    contacts: ContactSettings,
    choose: impl FnOnce(PluginGroupBuilder) -> PluginGroupBuilder,
) -> Result<App, Box<dyn Error>> {
    let mut app = App::new();
    let timestep = PhysicsTimestep::new(1.0 / 60.0, substeps)?;
    app.add_plugins(choose(UrtoPlugins::with_timestep(timestep).build()))
        .insert_resource(gravity)
        .insert_resource(contacts);
    Ok(app)
}

/// The recording options every game takes.
#[derive(clap::Args, Debug)]
pub struct RecordingArgs {
    /// Where to write the recording [default: <game>.rrd]
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Record every k-th step [default: the game's, 1 for most]
    #[arg(long)]
    pub every: Option<u64>,
    /// Open the viewer on the last recorded step (for screenshots).
    #[arg(long)]
    pub open_at_end: bool,
}

impl RecordingArgs {
    /// The recording's path: `--out`, else `<game>.rrd`.
    pub fn path(&self, game: &str) -> PathBuf {
        self.out
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("{game}.rrd")))
    }

    /// A recording of `game` to its file, every `--every` (else `every`) steps.
    pub fn config(&self, game: &str, every: u64) -> RerunConfig {
        RerunConfig {
            app_id: format!("urto {game}"),
            every_k_steps: self.every.unwrap_or(every),
            open_at_end: self.open_at_end,
            ..RerunConfig::file(self.path(game))
        }
    }
}

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
