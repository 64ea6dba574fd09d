//! An avalanche: a thousand bodies of the shapes games use — spheres, boxes, capsules and
//! convex-hull rocks — poured in waves into a static mesh bowl, where they tumble and roll
//! down the slope, pile up and fall asleep.
//!
//! The bowl is one triangle mesh, built here by revolving a profile (a paraboloid with a flat
//! rim) around the vertical axis. It is [`Static`], so the broad phase puts it in the uniform
//! grid (never in the sweep and prune), and every body touching it is tested against its OBB
//! hierarchy, down to the few triangles under the body, with its internal edges removed so that
//! bodies roll over the seams without bumps. The bodies meet each other through the incremental
//! sweep and prune, and convex pairs through closed forms (spheres, capsules, boxes) or GJK and
//! EPA (rocks against anything). Dynamic triangle meshes (`--mesh-bodies`) are the slow way to
//! model such props: each of their pairs is triangle against triangle.
//!
//! ```text
//! cargo run --release --example avalanche -- --help
//! rerun avalanche.rrd
//! ```
//!
//! Bodies are spawned at random orientations and turn on contact; a 1 cm lever arm against
//! rolling lets balls and capsules come to rest. Every body weighs 1 kg, sparing the contact
//! solver large mass ratios; `--mass-by-volume` gives each its volume's mass at 600 kg/m³
//! (ratios up to about 20:1). Everything the report prints is measured on the simulation.

mod support;

use bevy_app::App;
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;
use clap::Parser;
use glam::{EulerRot, Quat, Vec2, Vec3};
use std::error::Error;
use std::f32::consts::TAU;
use support::{Lcg, StepTimer};
use urto::debug::{DebugColor, RerunConfig, RerunDebugPlugin};
use urto::geometry::{MeshCollider, TriMesh};
use urto::plugins::Contacts;
use urto::prelude::*;

/// Bodies poured into a mesh bowl, recorded for the rerun viewer.
#[derive(Parser, Debug)]
struct Args {
    /// Bodies poured in all.
    #[arg(long, default_value_t = 1000)]
    bodies: u32,
    /// Waves they come in (one every half second).
    #[arg(long, default_value_t = 10)]
    waves: u32,
    /// Physics steps (60 per simulated second): the pile falls asleep at about 11–18 s (one
    /// straggler may roll on for a while).
    #[arg(long, default_value_t = 720)]
    steps: u32,
    /// Substeps per step (with 1, overlaps between bodies triple and now and then a body falls
    /// through the bowl, e.g. with `--seed 1`).
    #[arg(long, default_value_t = 2)]
    substeps: u32,
    /// Seed of the shapes, sizes and orientations.
    #[arg(long, default_value_t = 2024)]
    seed: u64,
    /// Give each body a mass by its volume (600 kg/m³) instead of 1 kg.
    #[arg(long)]
    mass_by_volume: bool,
    /// Make the rocks' share of bodies low-poly triangle meshes (balls and tori) instead, as
    /// this example did before convex shapes: slower, and the pile keeps jittering.
    #[arg(long)]
    mesh_bodies: bool,
    #[command(flatten)]
    recording: support::RecordingArgs,
}

/// Radius of the bowl's paraboloid, where the flat rim starts (m).
const BOWL_RADIUS: f32 = 7.5;
/// Height of the rim above the bottom (m): the wall is 47° steep at the rim, and steeper than
/// friction (0.4, 22°) holds beyond 2.8 m from the axis, so bodies landing there slide down.
const BOWL_DEPTH: f32 = 4.0;
/// Width of the flat rim around the bowl, where spilled bodies would come to rest (m).
const RIM: f32 = 1.5;
/// Steps between two waves.
const WAVE_EVERY: u32 = 30;
/// Distance between neighbours in a wave's block: wider than any body (bounding radius ≤ 0.45
/// m), so no two bodies start overlapping.
const SPACING: f32 = 0.95;
/// Speed below which a body counts as settled (m/s).
const SETTLED: f32 = 0.05;

/// The bowl's height at distance `r` from its axis: a paraboloid, then the flat rim.
fn bowl_height(r: f32) -> f32 {
    BOWL_DEPTH * (r / BOWL_RADIUS).min(1.0).powi(2)
}

/// The bowl: the profile revolved around z, as rings of vertices around a centre vertex (12
/// rings down the wall, one out to the rim's edge, 40 segments: triangles about as wide as the
/// bodies), triangles counter-clockwise seen from above, the side the bodies touch.
fn bowl_mesh() -> Result<MeshCollider, Box<dyn Error>> {
    let (rings, segments) = (12u32, 40u32);
    let mut vertices = vec![Vec3::ZERO];
    for i in 1..=rings + 1 {
        let r = BOWL_RADIUS * i as f32 / rings as f32;
        let r = if i > rings { BOWL_RADIUS + RIM } else { r };
        for j in 0..segments {
            let (s, c) = (TAU * j as f32 / segments as f32).sin_cos();
            vertices.push(Vec3::new(r * c, r * s, bowl_height(r)));
        }
    }
    let at = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, at(1, j), at(1, j + 1)]);
        for i in 1..=rings {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            triangles.extend([[a, b, c], [a, c, d]]);
        }
    }
    Ok(MeshCollider::named(
        "bowl",
        TriMesh::new(vertices, triangles)?,
    )?)
}

/// The kinds of body, coloured apart in the recording.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Sphere,
    Box,
    Capsule,
    Rock,
    MeshBall,
    MeshTorus,
}

impl Kind {
    fn color(self) -> DebugColor {
        DebugColor(match self {
            Kind::Sphere => [231, 111, 81],
            Kind::Box => [42, 157, 143],
            Kind::Capsule => [38, 70, 83],
            Kind::Rock => [233, 196, 106],
            Kind::MeshBall => [244, 162, 97],
            Kind::MeshTorus => [131, 56, 236],
        })
    }
}

/// A body to spawn: its kind and collider.
type Body = (Kind, Collider);

/// The small meshes `--mesh-bodies` shares between bodies (a handle each: the hierarchy is built
/// once per mesh).
struct BodyMeshes {
    balls: Vec<MeshCollider>,
    tori: Vec<MeshCollider>,
}

impl BodyMeshes {
    /// Low-poly balls (36 triangles) and tori (64 triangles), two sizes each: mesh–mesh tests
    /// cost per pair of triangles, so a thousand-body pile wants coarse meshes.
    fn new() -> Result<Self, Box<dyn Error>> {
        let ball = |r: f32| MeshCollider::named("ball", TriMesh::uv_sphere(r, 6, 4)?);
        let torus = |r: f32, t: f32| MeshCollider::named("torus", TriMesh::torus(r, t, 8, 4)?);
        Ok(Self {
            balls: vec![ball(0.26)?, ball(0.36)?],
            tori: vec![torus(0.24, 0.09)?, torus(0.32, 0.11)?],
        })
    }
}

/// A random body: 35% spheres, 30% boxes, 15% capsules and 20% rocks (with `meshes`, the rocks'
/// share is mesh balls and tori instead), sizes varied, none reaching more than 0.45 m from its
/// centre.
fn pick(rng: &mut Lcg, meshes: Option<&BodyMeshes>) -> Result<Body, Box<dyn Error>> {
    let roll = rng.next();
    Ok(if roll < 0.35 {
        sphere(rng.range(0.18, 0.4))
    } else if roll < 0.65 {
        let [x, y, z] = [0; 3].map(|_| rng.range(0.12, 0.26));
        (Kind::Box, Collider::cuboid(x, y, z))
    } else if roll < 0.8 {
        let (half_length, radius) = (rng.range(0.1, 0.25), rng.range(0.08, 0.18));
        (Kind::Capsule, Collider::capsule(half_length, radius))
    } else if let Some(meshes) = meshes {
        let (kind, list) = if roll < 0.9 {
            (Kind::MeshBall, &meshes.balls)
        } else {
            (Kind::MeshTorus, &meshes.tori)
        };
        (kind, Collider::mesh(list[rng.below(list.len())].clone()))
    } else {
        (Kind::Rock, rock(rng)?)
    })
}

/// A rock: the convex hull of 14 points scattered on an ellipsoid of semi-axes 0.18–0.36 m.
fn rock(rng: &mut Lcg) -> Result<Collider, Box<dyn Error>> {
    let axes = Vec3::from_array([0; 3].map(|_| rng.range(0.18, 0.36)));
    let points: Vec<Vec3> = (0..14)
        .map(|_| {
            let (z, angle) = (rng.range(-1.0, 1.0), rng.range(0.0, TAU));
            let ring = (1.0 - z * z).sqrt();
            Vec3::new(ring * angle.cos(), ring * angle.sin(), z) * axes
        })
        .collect();
    Ok(Collider::convex_hull(&points)?)
}

fn sphere(r: f32) -> Body {
    (Kind::Sphere, Collider::sphere(r))
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let recording = RerunDebugPlugin::new(RerunConfig {
        bounding_volumes: false,
        velocities: false,
        contacts: false,
        ..args.recording.config("avalanche", 2)
    })?;
    let mut app = support::game_app(
        args.substeps.max(1),
        Gravity::EARTH_Z_UP,
        ContactSettings {
            default_restitution: 0.1,
            default_friction: 0.4,
            ..Default::default()
        },
    )?;
    app.add_plugins(recording);
    let bowl = bowl_mesh()?;
    let triangles = bowl.mesh().triangle_count();
    let bowl = app
        .world_mut()
        .spawn((Collider::mesh(bowl), Static, DebugColor([200, 200, 210])))
        .id();
    let mut pour = Pour::new(&args)?;
    let (mut tally, mut timer) = (Tally::default(), StepTimer::start());
    for step in 0..args.steps {
        if step % WAVE_EVERY == 0 {
            pour.next_wave(&mut app)?;
        }
        urto::step(app.world_mut(), 1)?;
        timer.add(&app);
        tally.add(&app, bowl);
    }
    tally.print(&app, &args, &pour, &timer, triangles);
    Ok(())
}

/// The pour: blocks of bodies released above the bowl's wall, each wave from a spout turned two
/// fifths of a turn from the last (clear of the last wave, still falling), so the waves land on
/// different sides and slide to the middle.
struct Pour {
    meshes: Option<BodyMeshes>,
    rng: Lcg,
    per_wave: u32,
    left: u32,
    waves: u32,
    mass_by_volume: bool,
    bodies: Vec<(Entity, Kind)>,
}

impl Pour {
    fn new(args: &Args) -> Result<Self, Box<dyn Error>> {
        Ok(Self {
            meshes: args.mesh_bodies.then(BodyMeshes::new).transpose()?,
            rng: Lcg::new(args.seed),
            per_wave: args.bodies.div_ceil(args.waves.max(1)),
            left: args.bodies,
            waves: 0,
            mass_by_volume: args.mass_by_volume,
            bodies: Vec::new(),
        })
    }

    /// Spawns the next wave (if bodies are left) as a 5 × 5 block, as many layers tall as it
    /// takes, its bottom 1.5 m above the rim, thrown at 2 m/s down and towards the axis. Each
    /// body is turned at random; the last (top layer) is a sphere labelled with its wave's
    /// number, to show in the recording where each wave ended up.
    fn next_wave(&mut self, app: &mut App) -> Result<(), Box<dyn Error>> {
        let count = self.per_wave.min(self.left);
        if count == 0 {
            return Ok(());
        }
        let spout = Vec2::from_angle(self.waves as f32 * 2.0 * TAU / 5.0) * 0.55 * BOWL_RADIUS;
        let throw = (-spout.normalize()).extend(-1.7).normalize() * 2.0;
        let world = app.world_mut();
        for k in 0..count {
            let last = k + 1 == count;
            let (kind, collider) = if last {
                sphere(0.3)
            } else {
                pick(&mut self.rng, self.meshes.as_ref())?
            };
            let cell = Vec3::new(
                (k % 5) as f32 - 2.0,
                (k / 5 % 5) as f32 - 2.0,
                (k / 25) as f32,
            );
            let jitter = Vec2::new(self.rng.range(-0.02, 0.02), self.rng.range(-0.02, 0.02));
            let at = spout.extend(BOWL_DEPTH + 1.5) + cell * SPACING + jitter.extend(0.0);
            let turn = [0; 3].map(|_| self.rng.range(0.0, TAU));
            let mass = if self.mass_by_volume {
                collider.shape.mass_properties(600.0).mass
            } else {
                1.0
            };
            let mut body = world.spawn((
                collider,
                Position(at),
                Rotation(Quat::from_euler(EulerRot::XYZ, turn[0], turn[1], turn[2])),
                Velocity(throw),
                Mass(mass),
                // A 1 cm lever arm against rolling, so balls come to rest and the pile sleeps.
                RollingResistance(0.01),
                kind.color(),
            ));
            if last {
                body.insert(Name::new(format!("wave {}", self.waves + 1)));
            }
            self.bodies.push((body.id(), kind));
        }
        self.left -= count;
        self.waves += 1;
        Ok(())
    }
}

/// A per-step quantity: its mean and worst over the run, and its last value.
#[derive(Default)]
struct Series {
    sum: f64,
    worst: f64,
    last: f64,
    n: u32,
}

impl Series {
    fn add(&mut self, x: f64) {
        self.sum += x;
        self.worst = self.worst.max(x);
        self.last = x;
        self.n += 1;
    }

    fn mean(&self) -> f64 {
        self.sum / f64::from(self.n.max(1))
    }
}

/// What the run did, step by step: contacts, pairs, and the deepest overlaps (mm) the narrow
/// phase found (before the response pushed the bodies apart).
#[derive(Default)]
struct Tally {
    contacts: Series,
    pairs: Series,
    bowl_depth: Series,
    body_depth: Series,
}

impl Tally {
    /// Adds the step just run. Counters and contacts are those of the step's last substep.
    fn add(&mut self, app: &App, bowl: Entity) {
        let world = app.world();
        let stats = world.resource::<PhysicsStats>();
        let counter = |name| stats.counter(name).unwrap_or(0.0);
        self.contacts.add(counter("narrow_phase/contacts"));
        self.pairs
            .add(counter("broad_phase/pairs") + counter("broad_phase/static_pairs"));
        let (mut into_bowl, mut between) = (0.0f32, 0.0f32);
        for c in &world.resource::<Contacts>().pairs {
            let depth = c.manifold.max_depth();
            if c.b == bowl {
                into_bowl = into_bowl.max(depth);
            } else {
                between = between.max(depth);
            }
        }
        self.bowl_depth.add(f64::from(into_bowl) * 1e3);
        self.body_depth.add(f64::from(between) * 1e3);
    }

    fn print(&self, app: &App, args: &Args, pour: &Pour, timer: &StepTimer, triangles: usize) {
        let world = app.world();
        let stats = world.resource::<PhysicsStats>();
        let n = |kind| pour.bodies.iter().filter(|(_, k)| *k == kind).count();
        println!(
            "avalanche: {} bodies ({} spheres, {} boxes, {} capsules, {} rocks, {} mesh balls, {} mesh tori) poured in {} waves into a {triangles}-triangle static mesh bowl, {} steps of {} substeps ({:.1} s simulated)",
            pour.bodies.len(),
            n(Kind::Sphere),
            n(Kind::Box),
            n(Kind::Capsule),
            n(Kind::Rock),
            n(Kind::MeshBall),
            n(Kind::MeshTorus),
            pour.waves,
            stats.step,
            args.substeps.max(1),
            stats.sim_time
        );
        let end = Ending::measure(app, &pour.bodies);
        println!(
            "  at the end: {} inside the bowl, {} spilled onto the rim, {} below the bowl's surface (through it), {} NaN or quarantined",
            end.inside, end.on_rim, end.below, end.broken
        );
        println!(
            "  {} settled (speed < {SETTLED} m/s), {} of them asleep, {} still moving (fastest {:.2} m/s); highest body centre {:.2} m above the bottom (rim: {BOWL_DEPTH} m)",
            end.settled,
            end.asleep,
            pour.bodies.len() - end.settled,
            end.fastest,
            end.pile_top
        );
        for (what, s) in [
            ("into the bowl", &self.bowl_depth),
            ("between bodies", &self.body_depth),
        ] {
            println!(
                "  deepest overlap {what}: {:.0} mm worst step, {:.1} mm mean of each step's deepest, {:.1} mm in the last step",
                s.worst,
                s.mean(),
                s.last
            );
        }
        println!(
            "  per step: {:.0} contacts (worst {:.0}), {:.0} candidate pairs (worst {:.0}); the grid holds {} static",
            self.contacts.mean(),
            self.contacts.worst,
            self.pairs.mean(),
            self.pairs.worst,
            stats.counter("broad_phase/static_bodies").unwrap_or(0.0)
        );
        println!("  {}", timer.summary());
        support::print_recording(&args.recording.path("avalanche"));
    }
}

/// Where the bodies ended.
#[derive(Default)]
struct Ending {
    inside: usize,
    on_rim: usize,
    below: usize,
    broken: usize,
    settled: usize,
    asleep: usize,
    fastest: f32,
    pile_top: f32,
}

impl Ending {
    /// Sorts the bodies by where their centre is: above the paraboloid, out over the rim, or
    /// under the surface (which only a body that went through the mesh can be).
    fn measure(app: &App, bodies: &[(Entity, Kind)]) -> Self {
        let world = app.world();
        let mut end = Ending::default();
        for &(e, _) in bodies {
            let (Some(p), Some(v)) = (world.get::<Position>(e), world.get::<Velocity>(e)) else {
                continue;
            };
            if !p.0.is_finite() || world.get::<Quarantined>(e).is_some() {
                end.broken += 1;
                continue;
            }
            let r = p.0.truncate().length();
            if p.0.z < bowl_height(r) {
                end.below += 1;
            } else if r < BOWL_RADIUS {
                end.inside += 1;
                end.pile_top = end.pile_top.max(p.0.z);
            } else {
                end.on_rim += 1;
            }
            let speed = v.0.length();
            end.settled += usize::from(speed < SETTLED);
            end.asleep += usize::from(world.get::<Sleeping>(e).is_some());
            end.fastest = end.fastest.max(speed);
        }
        end
    }
}
