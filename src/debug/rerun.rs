//! Debug recording to rerun: the physics state of every (k-th) step, for viewing offline.
//!
//! The plugin is a consumer at the end of the step ([`PhysicsSet::Debug`]): it reads physics state
//! and writes nothing back, so a slow recording can only slow the program, never change a result.
//! It logs, on a `step` sequence timeline and a `sim_time` timeline:
//!
//! | entity path | what | archetype |
//! |---|---|---|
//! | `world/bodies/spheres`, `…/boxes`, `…/capsules` | moving bodies (orange dynamic, blue kinematic, red quarantined) | `Ellipsoids3D`, `Boxes3D`, `Capsules3D` |
//! | `world/static/...` | static scenery (grey), re-logged only when it changes | `Ellipsoids3D`, `Boxes3D`, `Capsules3D` |
//! | `world/meshes/<name>_<entity>` | each mesh body: its triangles once (grey static, orange dynamic, blue kinematic) and its pose per recorded step (static meshes: when moved) | `Mesh3D` + `Transform3D` |
//! | `hierarchy/level_<k>/moving`, `…/static` | the OBBs of level `k` (root 0) of every mesh's hierarchy, world space (static meshes' re-logged only when they change); only with [`RerunConfig::bvh_levels`], each level in its own tab of the layout | `Boxes3D` |
//! | `narrow_phase/overlapping_leaves` | the triangles of the hierarchy leaves through which meshes touched (cyan: first body, pink: second); only with [`RerunConfig::overlapping_leaves`] | `LineStrips3D` |
//! | `narrow_phase/overlapping_leaf_boxes` | the boxes of those leaves | `Boxes3D` |
//! | `world/bounding_volumes` | the world AABBs the broad phase reads (green wireframe) | `Boxes3D` |
//! | `world/velocities` | velocity arrows (yellow) | `Arrows3D` |
//! | `world/contacts` | contact points with their normals scaled by depth (magenta) | `Arrows3D` |
//! | `broad_phase/pairs` | candidate pairs as segments between centres | `LineStrips3D` |
//! | `world/joints/links`, `…/anchors`, `…/axes` | each joint's anchors, the segment between them (orange; red past a limit, grey disabled) and its axis at the first anchor | `LineStrips3D`, `Points3D`, `Arrows3D` |
//! | `joints/<entity>/force`, `…/torque`, `…/motor`, `joints/past_limit` | what the first 16 joints hold (N, N·m), what their motors apply (signed), and how far the worst joint is past its limit | `Scalars` |
//! | `broad_phase/grid_cells/occupied`, `…/empty` | the static grid's cells each moving body's volume touches (cyan: listing statics, dim blue: empty); only with [`RerunConfig::grid_cells`] | `Boxes3D` |
//! | `broad_phase/candidates/listed`, `…/overlapping` | the statics those cells list, as the grid stores them (yellow: listed, red: their box also overlaps a moving body's, so the pair goes to the narrow phase) | `Boxes3D` |
//! | `scene_graph/level_<k>` | the bounding volumes of depth `k` (root 0) of every body hierarchy (compound bodies), labelled with their [`Name`]; only with [`RerunConfig::scene_graph_levels`], each level in its own tab | `Boxes3D` |
//! | `scene_graph/visited/entered`, `…/pruned` | the hierarchy nodes the narrow phase's descent entered (yellow) and tested but pruned (grey) in the last substep; only with [`RerunConfig::hierarchy_visits`] (see [`HierarchyVisits`]) | `Boxes3D` |
//! | `scene_graph/visited/collider_pairs` | the collider pairs that descent handed to the exact test, as segments | `LineStrips3D` |
//! | `timing/<stage>` | wall time of each stage in the step, ms | `Scalars` |
//! | `counters/<name>` | the step's counters (pairs, contacts, refits, …) | `Scalars` |
//! | `log` | quarantine warnings | `TextLog` |
//!
//! Bodies are coloured by kind (a part of a compound by its root's kind) unless they carry a
//! [`DebugColor`]; sleeping bodies take a muted colour of their island (`body_colors.rs`);
//! bodies are labelled with their [`Name`] when they have one.
//!
//! Conversion to rerun's types happens here and only here: the rest of urto never sees rerun.

mod body_colors;
mod grid_cells;
mod joints;
mod layout;
mod meshes;
mod scene_graph;
mod shape_batch;

use body_colors::{KindView, STATIC, body_color};
use layout::default_layout;
use meshes::{LoggedMeshes, record_meshes, record_overlapping_leaves};
use shape_batch::ShapeBatch;

use crate::components::*;
use crate::geometry::{MeshCollider, Shape};
use crate::plugins::narrow_phase::{HierarchyVisits, NO_LEAF, OverlappingLeaves};
use crate::plugins::{BroadPhasePairs, Contacts};
use crate::schedule::{PhysicsSchedule, PhysicsSet};
use crate::stats::{PhysicsStats, Stage};
use bevy_app::prelude::*;
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;
use glam::{Quat, Vec3};
use rerun::RecordingStream;
use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;
use std::time::Instant;

/// Where the recording goes.
#[derive(Clone, Debug, PartialEq)]
pub enum RecordingSink {
    /// An `.rrd` file, created (truncated) when the plugin is made.
    File(PathBuf),
    /// A running viewer, by its gRPC proxy URL (`rerun+http://127.0.0.1:9876/proxy`).
    Connect(String),
}

/// Which world axis is up in the viewer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UpAxis {
    /// The slides' convention (gravity along -z).
    #[default]
    Z,
    /// Bevy's convention (gravity along -y).
    Y,
}

/// How and what to record.
#[derive(Clone, Debug, PartialEq)]
pub struct RerunConfig {
    /// The recording's application id, shown in the viewer.
    pub app_id: String,
    /// Where to send it.
    pub sink: RecordingSink,
    /// Log every k-th step only (1 = every step): long runs stay small.
    pub every_k_steps: u64,
    /// Which axis is up.
    pub up: UpAxis,
    /// Log bounding volumes (wireframes).
    pub bounding_volumes: bool,
    /// Log velocity arrows.
    pub velocities: bool,
    /// Log contacts and broad-phase pairs.
    pub contacts: bool,
    /// Half size of the square drawn for each half-space (they are infinite).
    pub plane_half_size: f32,
    /// Log the first `bvh_levels` levels of each mesh's hierarchy (0: none); the layout then
    /// shows one tab per level.
    pub bvh_levels: u32,
    /// Log the hierarchy leaves through which meshes touch, every recorded step. Makes the
    /// narrow phase record them (see
    /// [`OverlappingLeaves`]).
    pub overlapping_leaves: bool,
    /// Log, every recorded step, the static grid's cells each moving body's volume touches and
    /// the statics those cells list (the candidates the grid hands on); the layout then adds a
    /// close-up view of the moving bodies and their cells.
    pub grid_cells: bool,
    /// Log the bounding volumes of the first `scene_graph_levels` depths of every body hierarchy
    /// (0: none); the layout then shows one tab per level.
    pub scene_graph_levels: u32,
    /// Log which hierarchy nodes the narrow phase's descent of compound pairs entered and
    /// pruned. Makes the narrow phase record them (see [`HierarchyVisits`]).
    pub hierarchy_visits: bool,
    /// Open the viewer on the last recorded step (following new data as it arrives) instead of
    /// playing from the first: for screenshots, and for live viewers.
    pub open_at_end: bool,
}

impl RerunConfig {
    /// Everything recorded to a file, every step.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        Self {
            app_id: "urto".into(),
            sink: RecordingSink::File(path.into()),
            every_k_steps: 1,
            up: UpAxis::Z,
            bounding_volumes: true,
            velocities: true,
            contacts: true,
            plane_half_size: 10.0,
            bvh_levels: 0,
            overlapping_leaves: false,
            grid_cells: false,
            scene_graph_levels: 0,
            hierarchy_visits: false,
            open_at_end: false,
        }
    }
}

/// Why the recording could not start.
#[derive(Debug)]
pub enum RerunError {
    /// The sink could not be opened (unwritable path, bad URL, …).
    Sink(String),
    /// A setting is out of range.
    Config(String),
}

impl fmt::Display for RerunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Sink(e) => write!(f, "cannot open the rerun recording: {e}"),
            Self::Config(e) => write!(f, "bad rerun recording settings: {e}"),
        }
    }
}

impl std::error::Error for RerunError {}

/// Records the simulation to rerun. Made with [`RerunDebugPlugin::new`], which opens the sink
/// and fails there (not later) on an unwritable path.
#[derive(Clone)]
pub struct RerunDebugPlugin {
    recording: RecordingStream,
    config: RerunConfig,
}

impl fmt::Debug for RerunDebugPlugin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RerunDebugPlugin")
            .field("config", &self.config)
            .finish()
    }
}

impl RerunDebugPlugin {
    /// Opens the sink the config names.
    pub fn new(config: RerunConfig) -> Result<Self, RerunError> {
        if config.every_k_steps == 0 {
            return Err(RerunError::Config("every_k_steps must be >= 1".into()));
        }
        let app_id = rerun::ApplicationId::try_new(config.app_id.clone())
            .map_err(|e| RerunError::Config(e.to_string()))?;
        let builder = rerun::RecordingStreamBuilder::new(app_id);
        let recording = match &config.sink {
            RecordingSink::File(path) => builder.save(path),
            RecordingSink::Connect(url) => builder.connect_grpc_opts(url.as_str()),
        }
        .map_err(|e| RerunError::Sink(e.to_string()))?;
        Ok(Self::from_stream(recording, config))
    }

    /// Everything recorded to an `.rrd` file.
    pub fn to_file(path: impl Into<PathBuf>) -> Result<Self, RerunError> {
        Self::new(RerunConfig::file(path))
    }

    /// Records into a stream made by the caller (e.g. rerun's in-memory sink in tests); the
    /// config's sink is ignored.
    pub fn from_stream(recording: RecordingStream, config: RerunConfig) -> Self {
        Self { recording, config }
    }
}

/// The open recording, as a resource (game code may log its own entities to it).
#[derive(Resource, Clone)]
pub struct RerunRecording {
    /// The stream.
    pub stream: RecordingStream,
    /// The settings it was opened with.
    pub config: RerunConfig,
}

impl Plugin for RerunDebugPlugin {
    fn build(&self, app: &mut App) {
        let rec = &self.recording;
        // Wall-clock timestamps would make two recordings of the same run differ.
        rec.set_log_time_enabled(false);
        let coordinates = match self.config.up {
            UpAxis::Z => rerun::ViewCoordinates::RIGHT_HAND_Z_UP(),
            UpAxis::Y => rerun::ViewCoordinates::RIGHT_HAND_Y_UP(),
        };
        report(rec.log_static("world", &coordinates));
        report(default_layout(&self.config).send(rec, Default::default()));
        if self.config.overlapping_leaves {
            app.insert_resource(OverlappingLeaves {
                enabled: true,
                pairs: Vec::new(),
            });
        }
        if self.config.hierarchy_visits {
            app.insert_resource(HierarchyVisits {
                enabled: true,
                ..Default::default()
            });
        }
        app.init_resource::<DebugClock>()
            .init_resource::<LoggedMeshes>()
            .insert_resource(RerunRecording {
                stream: self.recording.clone(),
                config: self.config.clone(),
            })
            .add_systems(
                PhysicsSchedule,
                (
                    start_debug_clock,
                    record_statics,
                    record_bodies,
                    record_meshes,
                    record_pairs,
                    joints::record_joints,
                    record_overlapping_leaves,
                    grid_cells::record_grid_cells,
                    scene_graph::record_scene_graph_levels,
                    scene_graph::record_hierarchy_visits,
                    record_stats,
                )
                    .chain()
                    .run_if(is_recorded_step)
                    .in_set(PhysicsSet::Debug),
            );
    }

    fn cleanup(&self, _app: &mut App) {
        report(self.recording.flush_blocking());
    }
}

impl Drop for RerunRecording {
    fn drop(&mut self) {
        report(self.stream.flush_blocking());
    }
}

const BV: [u8; 3] = [46, 204, 113];
const VELOCITY: [u8; 3] = [241, 196, 15];
const CONTACT: [u8; 3] = [217, 70, 239];
const PAIR: [u8; 3] = [120, 120, 120];
const LEAF_A: [u8; 3] = [26, 188, 196];
const LEAF_B: [u8; 3] = [255, 99, 146];
/// Hierarchy levels cycle through these colours.
const LEVELS: [[u8; 3]; 6] = [
    [46, 204, 113],
    [52, 152, 219],
    [155, 89, 182],
    [241, 196, 15],
    [230, 126, 34],
    [231, 76, 60],
];

fn color([r, g, b]: [u8; 3]) -> rerun::Color {
    rerun::Color::from_rgb(r, g, b)
}

fn report<E: fmt::Display>(r: Result<(), E>) {
    if let Err(e) = r {
        log::warn!("urto: rerun logging failed: {e}");
    }
}

fn is_recorded_step(rec: Res<RerunRecording>, stats: Res<PhysicsStats>) -> bool {
    stats.step.is_multiple_of(rec.config.every_k_steps)
}

fn set_time(rec: &RecordingStream, stats: &PhysicsStats) {
    rec.set_time_sequence("step", stats.step as i64);
    rec.set_duration_secs("sim_time", stats.sim_time);
}

fn arr(v: Vec3) -> [f32; 3] {
    v.to_array()
}

fn quat(q: Quat) -> rerun::Quaternion {
    rerun::Quaternion::from_xyzw(q.to_array())
}

/// The colour a body is drawn in, instead of the colour of its kind (dynamic, kinematic,
/// static); e.g. to tell a game's targets from its walls. Only the recording reads it.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq)]
pub struct DebugColor(pub [u8; 3]);

type StaticChanged = (
    With<Static>,
    Or<(
        Added<Collider>,
        Changed<GlobalPose>,
        Changed<Collider>,
        Changed<DebugColor>,
    )>,
);

type StaticView<'a> = (
    &'a Collider,
    &'a GlobalPose,
    Option<&'a DebugColor>,
    Option<&'a Name>,
);

/// Static scenery, re-logged only on the steps where some of it was added, moved, recoloured
/// or removed.
fn record_statics(
    rec: Res<RerunRecording>,
    stats: Res<PhysicsStats>,
    changed: Query<(), StaticChanged>,
    removed: RemovedComponents<Static>,
    statics: Query<StaticView, With<Static>>,
) {
    if changed.is_empty() && removed.is_empty() {
        return;
    }
    set_time(&rec.stream, &stats);
    let mut batch = ShapeBatch::default();
    for (c, g, tint, name) in &statics {
        let (p, r) = (g.0.translation, g.0.rotation);
        let color = tint.map_or(STATIC, |t| t.0);
        batch.push(&c.shape, p, r, color, name, rec.config.plane_half_size);
    }
    batch.log(&rec.stream, "world/static");
}

type BodyView<'a> = (
    Entity,
    &'a Collider,
    &'a GlobalPose,
    &'a BoundingVolume,
    Option<&'a Velocity>,
    Option<&'a DebugColor>,
    Option<&'a Name>,
    (Has<Sleeping>, Option<&'a SleepState>),
);

/// Moving bodies, their bounding volumes and velocities.
fn record_bodies(
    rec: Res<RerunRecording>,
    stats: Res<PhysicsStats>,
    bodies: Query<BodyView, Without<Static>>,
    parents: Query<&ChildOf>,
    kinds: Query<KindView>,
    mut log_lines: Query<(Entity, &Quarantined), Added<Quarantined>>,
) {
    let stream = &rec.stream;
    set_time(stream, &stats);
    let mut batch = ShapeBatch::default();
    let (mut bv_centers, mut bv_half) = (Vec::new(), Vec::new());
    let (mut origins, mut vectors) = (Vec::new(), Vec::new());
    for (e, c, g, bv, v, tint, name, (asleep, sleep)) in &bodies {
        let (p, r) = (g.0.translation, g.0.rotation);
        let island = asleep.then(|| sleep.map_or(0, |s| s.island));
        let color = body_color(e, tint, island, &parents, &kinds);
        batch.push(&c.shape, p, r, color, name, rec.config.plane_half_size);
        if bv.0.is_finite() {
            bv_centers.push(arr(bv.0.center()));
            bv_half.push(arr(bv.0.half_extents()));
        }
        if let Some(v) = v.filter(|v| v.0 != Vec3::ZERO) {
            origins.push(arr(p));
            vectors.push(arr(v.0 * 0.1));
        }
    }
    batch.log(stream, "world/bodies");
    if rec.config.bounding_volumes {
        let boxes = rerun::Boxes3D::from_centers_and_half_sizes(bv_centers, bv_half)
            .with_colors([rerun::Color::from_rgb(BV[0], BV[1], BV[2])]);
        report(stream.log("world/bounding_volumes", &boxes));
    }
    if rec.config.velocities {
        let arrows = rerun::Arrows3D::from_vectors(vectors)
            .with_origins(origins)
            .with_colors([rerun::Color::from_rgb(
                VELOCITY[0],
                VELOCITY[1],
                VELOCITY[2],
            )]);
        report(stream.log("world/velocities", &arrows));
    }
    for (e, q) in log_lines.iter_mut() {
        let line = rerun::TextLog::new(format!("quarantined {e}: {}", q.reason))
            .with_level(rerun::TextLogLevel::WARN);
        report(stream.log("log", &line));
    }
}

/// Contacts (arrows along the normal, scaled by depth) and broad-phase pairs (segments between
/// the centres of bounded bodies).
fn record_pairs(
    rec: Res<RerunRecording>,
    contacts: Option<Res<Contacts>>,
    pairs: Option<Res<BroadPhasePairs>>,
    bodies: Query<(&GlobalPose, &BoundingVolume)>,
) {
    if !rec.config.contacts {
        return;
    }
    let stream = &rec.stream;
    if let Some(contacts) = contacts {
        let (mut origins, mut vectors) = (Vec::new(), Vec::new());
        for c in &contacts.pairs {
            for p in c.manifold.points() {
                origins.push(arr(p.point));
                vectors.push(arr(c.manifold.normal * (0.1 + p.depth)));
            }
        }
        let arrows = rerun::Arrows3D::from_vectors(vectors)
            .with_origins(origins)
            .with_colors([rerun::Color::from_rgb(CONTACT[0], CONTACT[1], CONTACT[2])]);
        report(stream.log("world/contacts", &arrows));
    }
    if let Some(pairs) = pairs {
        let strips: Vec<[[f32; 3]; 2]> = pairs
            .pairs
            .iter()
            .filter_map(|&(a, b)| {
                // Pairs with unbounded scenery (every body vs the ground) would only be clutter.
                let ((pa, ba), (pb, bb)) = (bodies.get(a).ok()?, bodies.get(b).ok()?);
                (ba.0.is_finite() && bb.0.is_finite())
                    .then(|| [arr(pa.0.translation), arr(pb.0.translation)])
            })
            .collect();
        let lines = rerun::LineStrips3D::new(strips)
            .with_colors([rerun::Color::from_rgb(PAIR[0], PAIR[1], PAIR[2])]);
        report(stream.log("broad_phase/pairs", &lines));
    }
}

/// When this step's recording began: the Debug stage times itself without writing to the
/// physics statistics (it stays a pure consumer).
#[derive(Resource, Default)]
struct DebugClock(Option<Instant>);

fn start_debug_clock(mut clock: ResMut<DebugClock>) {
    clock.0 = Some(Instant::now());
}

/// Per-stage wall time (ms) and the step's counters as time series.
fn record_stats(rec: Res<RerunRecording>, stats: Res<PhysicsStats>, clock: Res<DebugClock>) {
    let stream = &rec.stream;
    for stage in Stage::ALL {
        let t = match (stage, clock.0) {
            (Stage::Debug, Some(start)) => start.elapsed(),
            _ => stats.stage_time(stage),
        };
        let ms = t.as_secs_f64() * 1e3;
        report(stream.log(
            format!("timing/{}", stage.name()),
            &rerun::Scalars::single(ms),
        ));
    }
    for (name, value) in stats.counters() {
        report(stream.log(format!("counters/{name}"), &rerun::Scalars::single(*value)));
    }
}
