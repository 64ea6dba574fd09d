//! The little car: a compound body (a chassis with a cabin and four wheels as children, the
//! scene graph serving as its bounding-volume hierarchy) drives through a town of a few thousand
//! static buildings. A scripted driver steers it from crossing to crossing and now and then
//! swerves into a wall, and the car bounces off.
//!
//! The buildings are static, so they sit in the uniform grid (the slides' "object vs static
//! scene") and never in the sweep and prune; each step the car's volume finds its grid cells and
//! only the buildings listed there are tested. The recording shows those cells (cyan: listing
//! buildings, blue: empty) and the candidate buildings (yellow: listed, red: box overlapping the
//! car's, so tested exactly) in a close-up view next to the whole town.
//!
//! ```text
//! cargo run --release --example town_drive -- --help
//! rerun town_drive.rrd
//! ```

mod support;

use bevy_app::App;
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;
use clap::Parser;
use glam::{Quat, Vec2, Vec3};
use std::error::Error;
use support::{Collisions, Lcg, StepTimer};
use urto::debug::{DebugColor, RerunConfig, RerunDebugPlugin};
use urto::plugins::{BroadPhaseIndex, BroadPhasePairs};
use urto::prelude::*;

/// A car driving through a town, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Blocks along each side of the (square) town.
    #[arg(long, default_value_t = 14)]
    blocks: u32,
    /// Lots along each side of a block (one building per lot, a few left as parks).
    #[arg(long, default_value_t = 4)]
    lots: u32,
    /// Physics steps (60 per simulated second).
    #[arg(long, default_value_t = 1800)]
    steps: u32,
    /// Cruising speed of the car (m/s).
    #[arg(long, default_value_t = 12.0)]
    speed: f32,
    #[command(flatten)]
    recording: support::RecordingArgs,
}

/// Width of a lot (m); a building fills most of it.
const LOT: f32 = 7.0;
/// Width of a street (m), kerb to kerb.
const STREET: f32 = 10.0;
const CAR_MASS: f32 = 1200.0;
/// Chassis half extents; the wheels hang below it.
const CHASSIS: Vec3 = Vec3::new(2.0, 0.9, 0.4);
const WHEEL_RADIUS: f32 = 0.4;
/// Height of the chassis centre above the ground when the wheels touch it.
const RIDE_HEIGHT: f32 = 2.0 * WHEEL_RADIUS + 0.05;

/// The town's layout: blocks of lots between a grid of streets.
#[derive(Clone, Copy)]
struct Town {
    blocks: u32,
    lots: u32,
}

impl Town {
    /// Distance between two parallel street centre lines.
    fn pitch(&self) -> f32 {
        self.lots as f32 * LOT + STREET
    }

    /// The crossing `(i, j)`, `0..=blocks` each: where street centre lines meet.
    fn crossing(&self, i: i32, j: i32) -> Vec2 {
        let half = self.blocks as f32 * self.pitch() / 2.0;
        Vec2::new(i as f32, j as f32) * self.pitch() - Vec2::splat(half)
    }

    /// Half the side of the square holding every street.
    fn half_size(&self) -> f32 {
        self.blocks as f32 * self.pitch() / 2.0 + STREET
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let town = Town {
        blocks: args.blocks.max(1),
        lots: args.lots.max(1),
    };
    let recording = RerunDebugPlugin::new(RerunConfig {
        grid_cells: true,
        velocities: false,
        bounding_volumes: false,
        plane_half_size: town.half_size() + 20.0,
        ..args.recording.config("town_drive", 1)
    })?;
    let mut app = support::game_app(
        2,
        Gravity::EARTH_Z_UP,
        ContactSettings {
            default_restitution: 0.45,
            default_friction: 0.0,
            ..Default::default()
        },
    )?;
    app.add_plugins(recording);
    let (ground, buildings) = build_town(&mut app, town);
    let start = town.crossing(town.blocks as i32 / 2, town.blocks as i32 / 2);
    let car = spawn_car(&mut app, start);
    let mut driver = Driver::new(town, (town.blocks as i32 / 2, town.blocks as i32 / 2));
    let report = drive(&mut app, &args, car, ground, &mut driver)?;
    report.print(&app, &args, car, &driver, buildings.len());
    Ok(())
}

/// Spawns the ground and the town's buildings (static boxes, taller downtown); returns the
/// ground and the buildings.
fn build_town(app: &mut App, town: Town) -> (Entity, Vec<Entity>) {
    let mut rng = Lcg::new(11);
    let world = app.world_mut();
    let ground = world.spawn((Collider::half_space(Vec3::Z), Static)).id();
    let mut buildings = Vec::new();
    let pitch = town.pitch();
    for bi in 0..town.blocks {
        for bj in 0..town.blocks {
            let corner = town.crossing(bi as i32, bj as i32) + Vec2::splat(STREET / 2.0);
            for li in 0..town.lots {
                for lj in 0..town.lots {
                    if rng.next() < 0.04 {
                        continue; // a park
                    }
                    let centre = corner + (Vec2::new(li as f32, lj as f32) + 0.5) * LOT;
                    let downtown = (-(centre.length() / (2.5 * pitch)).powi(2)).exp();
                    let height = rng.range(4.0, 9.0) + 26.0 * downtown * rng.next();
                    let half = Vec3::new(
                        LOT / 2.0 - rng.range(0.4, 1.2),
                        LOT / 2.0 - rng.range(0.4, 1.2),
                        height / 2.0,
                    );
                    let shade = rng.range(0.75, 1.0);
                    let grey = |c: f32| (c * shade) as u8;
                    buildings.push(
                        world
                            .spawn((
                                Collider::cuboid(half.x, half.y, half.z),
                                Position(centre.extend(half.z)),
                                Static,
                                DebugColor([grey(200.0), grey(196.0), grey(188.0)]),
                            ))
                            .id(),
                    );
                }
            }
        }
    }
    (ground, buildings)
}

/// The car: a chassis (the root, which alone moves) with a cabin and four wheels as children.
fn spawn_car(app: &mut App, at: Vec2) -> Entity {
    let world = app.world_mut();
    let car = world
        .spawn((
            Collider::cuboid(CHASSIS.x, CHASSIS.y, CHASSIS.z),
            Position(at.extend(RIDE_HEIGHT)),
            Velocity::default(),
            Mass(CAR_MASS),
            LinearDrag(60.0),
            Restitution(0.6),
            Friction(0.0),
            DebugColor([214, 48, 49]),
            Name::new("car"),
        ))
        .id();
    world.spawn((
        Collider::cuboid(1.0, 0.8, 0.35),
        Position::new(-0.3, 0.0, CHASSIS.z + 0.35),
        ChildOf(car),
        DebugColor([116, 185, 255]),
    ));
    for (x, y) in [(-1.3, -0.85), (-1.3, 0.85), (1.3, -0.85), (1.3, 0.85)] {
        world.spawn((
            Collider::sphere(WHEEL_RADIUS),
            Position::new(x, y, WHEEL_RADIUS - RIDE_HEIGHT),
            ChildOf(car),
            DebugColor([45, 52, 54]),
        ));
    }
    car
}

/// The scripted driver: follows the streets from crossing to crossing, picking straight, left
/// or right at random on arrival, and swerves every few seconds.
struct Driver {
    town: Town,
    at: (i32, i32),
    heading: (i32, i32),
    rng: Lcg,
    crossings: u32,
}

impl Driver {
    fn new(town: Town, at: (i32, i32)) -> Self {
        Self {
            town,
            at,
            heading: (1, 0),
            rng: Lcg::new(5),
            crossings: 0,
        }
    }

    /// The crossing the car comes from and the one it heads for.
    fn segment(&self) -> (Vec2, Vec2) {
        let (i, j) = self.at;
        let (dx, dy) = self.heading;
        (self.town.crossing(i, j), self.town.crossing(i + dx, j + dy))
    }

    /// On reaching the target crossing, turns left, right or goes on (never off the map).
    fn next_crossing(&mut self) {
        self.at = (self.at.0 + self.heading.0, self.at.1 + self.heading.1);
        self.crossings += 1;
        let (dx, dy) = self.heading;
        let options = [(dx, dy), (-dy, dx), (dy, -dx), (-dx, -dy)];
        let n = self.town.blocks as i32;
        let fits = |(x, y): (i32, i32)| (0..=n).contains(&x) && (0..=n).contains(&y);
        let open: Vec<(i32, i32)> = options[..3]
            .iter()
            .copied()
            .filter(|&(x, y)| fits((self.at.0 + x, self.at.1 + y)))
            .collect();
        self.heading = if open.is_empty() {
            options[3]
        } else {
            open[self.rng.below(open.len())]
        };
    }

    /// The horizontal force for this step: follow the street's centre line at cruising speed,
    /// slowing down before each crossing; during a swerve the wanted direction is turned
    /// 50–70 degrees, which usually ends against a wall.
    fn force(&mut self, p: Vec2, v: Vec2, t: f32, cruise: f32) -> Vec2 {
        let (mut from, mut to) = self.segment();
        if (to - p).dot((to - from).normalize_or_zero()) < 2.5 {
            self.next_crossing();
            (from, to) = self.segment();
        }
        let dir = (to - from).normalize_or_zero();
        let left = dir.perp();
        let off_centre = (p - from).dot(left);
        let remaining = (to - p).dot(dir);
        let speed = cruise.min(4.0 + 0.6 * remaining.max(0.0));
        let angle = swerve_angle(t);
        let wanted = if angle == 0.0 {
            dir * speed + left * (-0.8 * off_centre).clamp(-4.0, 4.0)
        } else {
            Vec2::from_angle(angle).rotate(dir) * speed
        };
        ((wanted - v) * CAR_MASS * 2.5).clamp_length_max(CAR_MASS * 7.0)
    }
}

/// Seconds between the starts of two swerves, and how long one lasts.
const SWERVE_EVERY: f32 = 4.0;
const SWERVE_FOR: f32 = 1.5;

/// How far (radians) the driver turns off the street at time `t`: a swerve of 1.1 radians,
/// alternately left and right, starting every [`SWERVE_EVERY`] seconds. Most end against a
/// wall (the street leaves about 4 m on each side of the car).
fn swerve_angle(t: f32) -> f32 {
    let k = (t / SWERVE_EVERY).floor();
    let into = t - k * SWERVE_EVERY - (SWERVE_EVERY - SWERVE_FOR);
    if k < 1.0 || !(0.0..SWERVE_FOR).contains(&into) {
        return 0.0;
    }
    if k as i32 % 2 == 0 { 1.1 } else { -1.1 }
}

/// What happened during the drive.
struct DriveReport {
    crashes: u32,
    distance: f32,
    top_speed: f32,
    grid: GridWork,
    timer: StepTimer,
}

/// What the static grid did for the car, summed over the steps.
#[derive(Default)]
struct GridWork {
    /// Cells the car's volume touched.
    cells: u64,
    /// Buildings (and walls) listed in those cells, each once.
    listed: u64,
    /// Pairs with statics handed to the narrow phase (their boxes overlap), ground excluded.
    tested: u64,
    steps: u64,
    ids: Vec<u32>,
    in_cell: Vec<u32>,
}

impl GridWork {
    /// Adds the step just run, from the car's volume and the broad phase's pairs.
    fn add(&mut self, app: &App, car: Entity, ground: Entity) {
        let world = app.world();
        let grid = world.resource::<BroadPhaseIndex>().grid();
        let Some(bv) = world.get::<BoundingVolume>(car) else {
            return;
        };
        let Ok(range) = grid.cells_touching(&bv.0) else {
            return;
        };
        self.ids.clear();
        for cell in range.iter() {
            grid.objects_in_cell(cell, &mut self.in_cell);
            self.ids.extend_from_slice(&self.in_cell);
        }
        self.ids.sort_unstable();
        self.ids.dedup();
        self.cells += range.cell_count() as u64;
        self.listed += self.ids.len() as u64;
        let pairs = &world.resource::<BroadPhasePairs>().pairs;
        self.tested += pairs.iter().filter(|p| p.1 != ground).count() as u64;
        self.steps += 1;
    }

    fn per_step(&self, total: u64) -> f64 {
        total as f64 / self.steps.max(1) as f64
    }
}

/// Runs the simulation, driving the car each step; counts crashes into buildings and walls.
fn drive(
    app: &mut App,
    args: &Args,
    car: Entity,
    ground: Entity,
    driver: &mut Driver,
) -> Result<DriveReport, Box<dyn Error>> {
    let dt = 1.0 / 60.0;
    let mut collisions = Collisions::new(app);
    let mut report = DriveReport {
        crashes: 0,
        distance: 0.0,
        top_speed: 0.0,
        grid: GridWork::default(),
        timer: StepTimer::start(),
    };
    let mut last = app.world().get::<Position>(car).map_or(Vec3::ZERO, |p| p.0);
    for step in 0..args.steps {
        let t = step as f32 * dt;
        let (p, v) = body_state(app, car);
        let f = driver.force(p.truncate(), v.truncate(), t, args.speed);
        steer(app, car, f, v);
        urto::step(app.world_mut(), 1)?;
        report.timer.add(app);
        report.crashes += collisions
            .read(app)
            .iter()
            .filter(|&&(a, b)| (a == car || b == car) && a != ground && b != ground)
            .count() as u32;
        let (p, v) = body_state(app, car);
        report.distance += (p - last).truncate().length();
        report.top_speed = report.top_speed.max(v.truncate().length());
        last = p;
        report.grid.add(app, car, ground);
    }
    Ok(report)
}

fn body_state(app: &App, e: Entity) -> (Vec3, Vec3) {
    let p = app.world().get::<Position>(e).map_or(Vec3::ZERO, |p| p.0);
    let v = app.world().get::<Velocity>(e).map_or(Vec3::ZERO, |v| v.0);
    (p, v)
}

/// Applies the driver's force and turns the car to face where it is going (urto's bodies do
/// not spin by themselves: the heading is the game's to set).
fn steer(app: &mut App, car: Entity, force: Vec2, v: Vec3) {
    let mut entity = app.world_mut().entity_mut(car);
    if let Some(mut f) = entity.get_mut::<Force>() {
        f.0 += force.extend(0.0);
    } else {
        entity.insert(Force(force.extend(0.0)));
    }
    if v.truncate().length() > 1.0
        && let Some(mut r) = entity.get_mut::<Rotation>()
    {
        let facing = Quat::from_rotation_z(v.y.atan2(v.x));
        let turned = r.0.slerp(facing, 0.15);
        r.0 = turned;
    }
}

impl DriveReport {
    fn print(&self, app: &App, args: &Args, car: Entity, driver: &Driver, buildings: usize) {
        let town = driver.town;
        let world = app.world();
        let stats = world.resource::<PhysicsStats>();
        let grid = world.resource::<BroadPhaseIndex>().grid();
        let (p, _) = body_state(app, car);
        println!(
            "town_drive: a car (chassis + cabin + 4 wheels) among {buildings} buildings on {} blocks, {} steps ({:.0} s simulated)",
            town.blocks * town.blocks,
            stats.step,
            stats.sim_time
        );
        println!(
            "  drove {:.0} m through {} crossings, top speed {:.1} m/s, {} crashes into buildings",
            self.distance, driver.crossings, self.top_speed, self.crashes
        );
        println!(
            "  static grid: {} statics in {} cells of {:.1} m; per step the car touched {:.1} cells listing {:.1} statics, {:.2} of them overlapping its box (tested exactly)",
            grid.len(),
            grid.occupied_cell_count(),
            grid.cell_size().x,
            self.grid.per_step(self.grid.cells),
            self.grid.per_step(self.grid.listed),
            self.grid.per_step(self.grid.tested),
        );
        let inside = p.truncate().abs().max_element() < town.half_size();
        println!(
            "  the car ends at ({:.1}, {:.1}, {:.2}), {}",
            p.x,
            p.y,
            p.z,
            if p.is_finite() && inside {
                "inside the town"
            } else {
                "OUTSIDE THE TOWN"
            }
        );
        println!("  {}", self.timer.summary());
        support::print_recording(&args.recording.path("town_drive"));
    }
}
