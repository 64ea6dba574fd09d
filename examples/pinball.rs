//! Pinball: fast balls against thin walls, played twice (once with the discrete step alone,
//! once with continuous collision) to count the balls lost through the walls.
//!
//! The walls are 2 cm thick, the balls 24 cm across; a plunger launches each ball at 28–36 m/s
//! and pop bumpers score and kick it away. Gravity lies in the table's plane, along its "down"
//! (6 m/s², as on a table tilted by 38°). At 30 m/s a ball travels 25 cm in a substep of 1/120 s,
//! more than its radius plus a wall: the discrete step may find it past the middle of a wall and
//! push it out on the far side, or not find it in the wall at all (tunnelling).
//!
//! The slides' first cure is more substeps, paid by every body (`--substeps 4` is enough here).
//! The second is continuous collision: with [`Ccd`] on the balls, each substep a ball's motion
//! is swept against the static walls and bumpers; it stops at the first time of impact (exact:
//! a ray against the obstacle inflated by the ball's radius, cross-checked in the crate by
//! conservative advancement), bounces there, and spends the rest of the substep from there.
//! Both runs follow the same rules with the same sequence of plunger strengths.
//!
//! With `--balls 3` (multiball), `--substeps 1` and 12,000 steps, 200 balls go through walls
//! without CCD and none with it: a ball shoved against a wall by another starts its substep
//! touching the wall, and the sweep takes that contact as an impact when the ball moves into it.
//! Balls meeting each other are still left to the discrete step (CCD sweeps against statics).
//!
//! ```text
//! cargo run --release --example pinball -- --help
//! rerun pinball.rrd
//! ```

mod support;

use bevy_app::App;
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;
use clap::Parser;
use glam::{Quat, Vec2, Vec3};
use std::collections::BTreeMap;
use std::error::Error;
use support::{Collisions, Lcg, StepTimer};
use urto::debug::rerun::RerunRecording;
use urto::debug::{DebugColor, RerunConfig, RerunDebugPlugin};
use urto::plugins::{CcdImpacts, CcdSettings};
use urto::prelude::*;

/// A pinball table played with and without continuous collision, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Physics steps of 1/60 s per run.
    #[arg(long, default_value_t = 1500)]
    steps: u32,
    /// Substeps per step (the same in both runs).
    #[arg(long, default_value_t = 2)]
    substeps: u32,
    /// Balls on the table at once: 1 as in a game, more for multiball.
    #[arg(long, default_value_t = 1)]
    balls: usize,
    /// Record the run without continuous collision instead (to watch balls tunnel).
    #[arg(long)]
    no_ccd: bool,
    #[command(flatten)]
    recording: support::RecordingArgs,
}

const RADIUS: f32 = 0.12;
/// Half the thickness of every wall.
const WALL_HALF: f32 = 0.01;
/// The outer walls' centre lines: x = ±HALF.x, y = ±HALF.y (table coordinates).
const HALF: Vec2 = Vec2::new(2.0, 3.2);
/// The plunger lane lies between x = LANE_X and the right wall.
const LANE_X: f32 = 1.7;
const TABLE_GRAVITY: f32 = 6.0;
const BUMPER_RADIUS: f32 = 0.28;
/// Speed a pop bumper adds, away from its centre, to a ball that starts touching it.
const KICK: f32 = 4.0;
const POINTS_PER_BUMPER: u32 = 100;
/// Least time between two launches (steps).
const LAUNCH_GAP: u32 = 60;
/// Below this, a ball outside the plunger lane has gone down the drain.
const DRAIN_Y: f32 = 0.45 - HALF.y;
/// Steps of trail drawn behind each ball.
const TRAIL: usize = 120;

/// A point or direction of the table (x across, y up the table) in the world: the table stands
/// in the x–z plane, facing the viewer's default camera (which looks along +y).
fn to_world(v: Vec2) -> Vec3 {
    Vec3::new(v.x, 0.0, v.y)
}

fn on_table(p: Vec3) -> Vec2 {
    Vec2::new(p.x, p.z)
}

/// A wall: what it is, and its centre line from `a` to `b`.
struct Wall {
    what: &'static str,
    a: Vec2,
    b: Vec2,
}

impl Wall {
    /// True if a centre going from `p` to `q` crossed the wall's centre line between its ends:
    /// the ball went *through* the wall (its centre cannot get there otherwise).
    fn crossed(&self, p: Vec2, q: Vec2) -> bool {
        let along = (self.b - self.a).normalize();
        let side = |x: Vec2| along.perp_dot(x - self.a);
        let (sp, sq) = (side(p), side(q));
        if sp * sq >= 0.0 {
            return false;
        }
        let at = p + (q - p) * (sp / (sp - sq));
        (0.0..=(self.b - self.a).length()).contains(&(at - self.a).dot(along))
    }
}

/// The static scenery: the walls, and each bumper with its centre.
struct Table {
    walls: Vec<Wall>,
    bumpers: Vec<(Entity, Vec2)>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let recording = RerunDebugPlugin::new(RerunConfig {
        contacts: false,
        bounding_volumes: false,
        ..args.recording.config("pinball", 1)
    })?;
    let (mut with, mut without) = (Some(recording), None);
    if args.no_ccd {
        std::mem::swap(&mut with, &mut without);
    }
    let discrete = play(&args, false, without)?;
    let continuous = play(&args, true, with)?;
    print_report(&args, &discrete, &continuous);
    Ok(())
}

/// CCD impacts summed over the substeps ([`CcdImpacts`] holds the current substep's only).
#[derive(Resource, Default)]
struct ImpactTally(u64);

fn tally_impacts(impacts: Res<CcdImpacts>, mut tally: ResMut<ImpactTally>) {
    tally.0 += impacts.contacts.len() as u64;
}

/// The app of one run. Automatic sweeping of fast unmarked bodies is off, so only the balls
/// marked [`Ccd`] (in the continuous run) are swept. The game runs the lecture's pipeline, whose
/// discrete detection in each substep is what lets balls through: the rigid-body solver (the
/// default) looks ahead by each ball's motion and stops these balls without CCD.
fn build_app(args: &Args, recording: Option<RerunDebugPlugin>) -> Result<App, Box<dyn Error>> {
    let mut app = support::lecture_game_app(
        args.substeps,
        Gravity::new(to_world(Vec2::NEG_Y * TABLE_GRAVITY))?,
        ContactSettings {
            default_friction: 0.0,
            ..Default::default()
        },
    )?;
    app.insert_resource(CcdSettings {
        auto_speed_ratio: None,
        ..Default::default()
    })
    .init_resource::<ImpactTally>()
    .add_systems(
        SubstepSchedule,
        tally_impacts.in_set(SubstepSet::BroadPhase),
    );
    if let Some(recording) = recording {
        app.add_plugins(recording);
    }
    Ok(app)
}

/// The walls: what each is, its centre line, and whether the recording labels it.
fn wall_lines() -> [(&'static str, Vec2, Vec2, bool); 9] {
    let (x, y) = (HALF.x, HALF.y);
    let v = Vec2::new;
    [
        ("left wall", v(-x, -y), v(-x, y), false),
        ("right wall", v(x, -y), v(x, y), false),
        ("top wall", v(-x, y), v(x, y), false),
        ("drain", v(-x, -y), v(x, -y), true),
        ("plunger lane", v(LANE_X, -y), v(LANE_X, y - 1.4), true),
        ("right deflector", v(1.3, y), v(x, y - 0.7), false),
        ("left deflector", v(-x, y - 0.7), v(-1.3, y), false),
        ("left funnel", v(-x, 1.6 - y), v(-0.45, 0.6 - y), false),
        ("right funnel", v(LANE_X, 1.6 - y), v(0.45, 0.6 - y), false),
    ]
}

/// Spawns a wall as a thin box along its centre line, a little longer than the line so that
/// walls meeting at a corner leave no gap; the outer frame dark, the guides light.
fn spawn_wall(world: &mut World, (what, a, b, label): (&'static str, Vec2, Vec2, bool)) -> Wall {
    let d = b - a;
    let outer = what.ends_with("wall") || what == "drain";
    world.spawn((
        // Local x along the wall, y across the table's plane (its height), z its thickness.
        Collider::cuboid(d.length() / 2.0 + WALL_HALF, 0.13, WALL_HALF),
        Position(to_world((a + b) / 2.0)),
        Rotation(Quat::from_rotation_y(-d.y.atan2(d.x))),
        Static,
        Restitution(0.5),
        DebugColor(if outer { [60, 60, 70] } else { [190, 190, 200] }),
        Name::new(if label { what } else { "" }),
    ));
    Wall { what, a, b }
}

/// The table: outer walls, the plunger lane, two corner deflectors, a funnel to the drain, and
/// five pop bumpers; the playfield and the cabinet behind it are only drawn (the balls glide
/// 5 mm in front of them).
fn build_table(app: &mut App) -> Table {
    let world = app.world_mut();
    for (margin, depth, color) in [(0.0, 0.0, [24, 44, 74]), (0.9, 0.1, [92, 60, 40])] {
        world.spawn((
            Collider::cuboid(HALF.x + margin, 0.05, HALF.y + margin),
            Position::new(0.0, RADIUS + 0.055 + depth, 0.0),
            Static,
            DebugColor(color),
        ));
    }
    let walls = wall_lines().map(|line| spawn_wall(world, line)).into();
    let spots = [
        [-0.7, 1.6],
        [0.7, 1.6],
        [0.0, 0.7],
        [-1.0, -0.5],
        [1.0, -0.5],
    ];
    let bumpers = (1..).zip(spots).map(|(i, at)| {
        let at = Vec2::from_array(at);
        let bumper = world.spawn((
            Collider::sphere(BUMPER_RADIUS),
            Position(to_world(at)),
            Static,
            Restitution(0.7),
            DebugColor([230, 60, 120]),
            Name::new(format!("bumper {i}")),
        ));
        (bumper.id(), at)
    });
    let bumpers = bumpers.collect();
    Table { walls, bumpers }
}

/// A ball at the bottom of the plunger lane.
fn spawn_ball(app: &mut App, ccd: bool, number: u32) -> Entity {
    let mut ball = app.world_mut().spawn((
        Collider::sphere(RADIUS),
        Position(to_world(Vec2::new((LANE_X + HALF.x) / 2.0, 0.3 - HALF.y))),
        Velocity::default(),
        Restitution(0.9),
        Friction(0.0),
        DebugColor([230, 230, 235]),
        Name::new(format!("ball {number}")),
    ));
    if ccd {
        ball.insert(Ccd);
    }
    ball.id()
}

/// What happened in one run, all read from the simulation.
#[derive(Default)]
struct RunReport {
    launched: u32,
    drained: u32,
    /// Balls lost through each wall, by wall (sorted: a deterministic report).
    lost_through: BTreeMap<&'static str, u32>,
    /// Balls whose centre ended a step outside the outer walls.
    left_table: u32,
    bumper_hits: u32,
    ccd_impacts: u64,
    top_speed: f32,
    /// [`StepTimer::summary`] at the end of the run.
    timing: String,
}

impl RunReport {
    fn lost(&self) -> u32 {
        self.lost_through.values().sum()
    }
}

/// Plays one run: a new ball whenever fewer than `--balls` are in play (at most one per
/// [`LAUNCH_GAP`] steps), the plunger and the bumpers acting between steps, and the referee
/// checking every ball after each step.
fn play(
    args: &Args,
    ccd: bool,
    recording: Option<RerunDebugPlugin>,
) -> Result<RunReport, Box<dyn Error>> {
    let mut app = build_app(args, recording)?;
    let table = build_table(&mut app);
    let mut collisions = Collisions::new(&app);
    let mut plunger = Lcg::new(3);
    let (mut balls, mut trails) = (Vec::new(), Trails::default());
    let mut report = RunReport::default();
    let mut timer = StepTimer::start();
    let mut next_launch = 0;
    for step in 0..args.steps {
        if balls.len() < args.balls && step >= next_launch {
            next_launch = step + LAUNCH_GAP;
            report.launched += 1;
            balls.push(spawn_ball(&mut app, ccd, report.launched));
        }
        plunge(&mut app, &balls, &mut plunger);
        let before: Vec<Vec2> = balls.iter().map(|&b| position(&app, b)).collect();
        urto::step(app.world_mut(), 1)?;
        timer.add(&app);
        let started = collisions.read(&app);
        report.bumper_hits += pop_bumpers(&mut app, &table, &started);
        balls = referee(&mut app, &table, balls, &before, &mut report);
        trails.update(&app, &balls)?;
    }
    report.ccd_impacts = app.world().resource::<ImpactTally>().0;
    report.timing = timer.summary();
    Ok(report)
}

fn position(app: &App, ball: Entity) -> Vec2 {
    app.world()
        .get::<Position>(ball)
        .map_or(Vec2::ZERO, |p| on_table(p.0))
}

/// The plunger: a ball at rest (or falling) at the bottom of the lane is shot up at 28–36 m/s.
/// Scripted, as the plunger's spring is the player's: it sets the ball's velocity.
fn plunge(app: &mut App, balls: &[Entity], rng: &mut Lcg) {
    for &ball in balls {
        let p = position(app, ball);
        let Some(mut v) = app.world_mut().get_mut::<Velocity>(ball) else {
            continue;
        };
        if p.x > LANE_X && p.y < 0.6 - HALF.y && on_table(v.0).y <= 0.0 {
            v.0 = to_world(Vec2::new(0.0, rng.range(28.0, 36.0)));
        }
    }
}

/// The pop bumpers: each collision that started with a bumper scores, and the bumper kicks the
/// ball away from its centre by [`KICK`]. Scripted like a real bumper's solenoid: a restitution
/// above 1 would multiply the speed instead, and a ball bouncing between two bumpers would
/// speed up without bound. Returns the hits.
fn pop_bumpers(app: &mut App, table: &Table, started: &[(Entity, Entity)]) -> u32 {
    let mut hits = 0;
    for &(a, b) in started {
        for &(bumper, centre) in &table.bumpers {
            let ball = match (a == bumper, b == bumper) {
                (true, _) => b,
                (_, true) => a,
                _ => continue,
            };
            let away = (position(app, ball) - centre).normalize_or_zero();
            if let Some(mut v) = app.world_mut().get_mut::<Velocity>(ball) {
                v.0 += to_world(away * KICK);
                hits += 1;
            }
        }
    }
    hits
}

/// Checks every ball after the step: one whose centre crossed a wall went through it and is
/// out of the game, as is one outside the outer walls or down the drain. Returns the balls
/// still in play.
fn referee(
    app: &mut App,
    table: &Table,
    balls: Vec<Entity>,
    before: &[Vec2],
    report: &mut RunReport,
) -> Vec<Entity> {
    let mut in_play = Vec::with_capacity(balls.len());
    for (&ball, &p) in balls.iter().zip(before) {
        let q = position(app, ball);
        let v = app
            .world()
            .get::<Velocity>(ball)
            .map_or(0.0, |v| v.0.length());
        report.top_speed = report.top_speed.max(v);
        let through = table.walls.iter().find(|w| w.crossed(p, q));
        if let Some(wall) = through {
            *report.lost_through.entry(wall.what).or_default() += 1;
        }
        let outside = q.x.abs() > HALF.x || q.y.abs() > HALF.y || !q.is_finite();
        let drained = q.y < DRAIN_Y && q.x < LANE_X && through.is_none();
        report.left_table += outside as u32;
        report.drained += drained as u32;
        if through.is_some() || outside || drained {
            app.world_mut().despawn(ball);
        } else {
            in_play.push(ball);
        }
    }
    in_play
}

/// The last [`TRAIL`] positions of each ball, logged to the recording's stream (game code may
/// log its own entities there); the trail of a ball taken off the table shrinks away.
#[derive(Default)]
struct Trails(Vec<(Entity, Vec<Vec3>)>);

impl Trails {
    fn update(&mut self, app: &App, balls: &[Entity]) -> Result<(), Box<dyn Error>> {
        let world = app.world();
        let Some(rec) = world.get_resource::<RerunRecording>() else {
            return Ok(());
        };
        for &ball in balls {
            if self.0.iter().all(|t| t.0 != ball) {
                self.0.push((ball, Vec::new()));
            }
        }
        for (ball, points) in &mut self.0 {
            let at = world.get::<Position>(*ball);
            points.extend(at.map(|p| p.0));
            if points.len() > TRAIL || at.is_none() {
                points.remove(0);
            }
        }
        self.0.retain(|(_, points)| !points.is_empty());
        let stats = world.resource::<PhysicsStats>();
        if stats.step.is_multiple_of(rec.config.every_k_steps) {
            rec.stream.set_time_sequence("step", stats.step as i64);
            rec.stream.set_duration_secs("sim_time", stats.sim_time);
            let strips = self.0.iter().map(|t| t.1.iter().map(|p| p.to_array()));
            let lines = rerun::LineStrips3D::new(strips)
                .with_colors([rerun::Color::from_rgb(110, 210, 255)])
                .with_radii([rerun::Radius::new_scene_units(0.02)]);
            rec.stream.log("world/trails", &lines)?;
        }
        Ok(())
    }
}

fn print_report(args: &Args, discrete: &RunReport, continuous: &RunReport) {
    println!(
        "pinball: balls of radius {RADIUS} m, walls {:.0} cm thick, {} ball(s) in play; {} steps of 1/60 s with {} substeps ({:.0} s simulated)",
        2.0 * WALL_HALF * 100.0,
        args.balls,
        args.steps,
        args.substeps,
        args.steps as f32 / 60.0,
    );
    println!("                                without CCD   with CCD (Ccd on the balls)");
    let row = |what: &str, f: &dyn Fn(&RunReport) -> String| {
        println!("  {what:<28}{:>13}   {:>8}", f(discrete), f(continuous));
    };
    row("balls launched", &|r| r.launched.to_string());
    row("bumper hits (score)", &|r| {
        format!("{} ({})", r.bumper_hits, r.bumper_hits * POINTS_PER_BUMPER)
    });
    row("balls drained", &|r| r.drained.to_string());
    row("BALLS LOST THROUGH A WALL", &|r| r.lost().to_string());
    row("  of which left the table", &|r| r.left_table.to_string());
    row("CCD impacts", &|r| r.ccd_impacts.to_string());
    row("top speed (m/s)", &|r| format!("{:.1}", r.top_speed));
    for (what, r) in [("without CCD", discrete), ("with CCD", continuous)] {
        let walls: Vec<String> = (r.lost_through.iter())
            .map(|(wall, n)| format!("{wall} {n}"))
            .collect();
        let walls = if walls.is_empty() {
            "none".into()
        } else {
            walls.join(", ")
        };
        println!("  {what}: balls lost through {walls}; {}", r.timing);
    }
    let recorded = if args.no_ccd { "without" } else { "with" };
    println!("  the recording shows the run {recorded} CCD");
    support::print_recording(&args.recording.path("pinball"));
}
