//! Meshes in the recording: each mesh body's triangles logged once and moved by its pose, and
//! the hierarchy leaves through which two meshes touched.

use super::body_colors::{kind_tint, sleeping_color};
use super::*;

/// The entity path of each mesh body logged so far and the colour it was last drawn with
/// (sorted by entity: deterministic).
#[derive(Resource, Default)]
pub(super) struct LoggedMeshes(BTreeMap<Entity, (String, [u8; 3])>);

type MeshBody<'a> = (
    Entity,
    Ref<'a, Collider>,
    Ref<'a, GlobalPose>,
    Has<Static>,
    Option<&'a ComputedMass>,
    Option<&'a DebugColor>,
    (Has<Sleeping>, Option<&'a SleepState>),
);

/// Mesh bodies: the triangles once per body (again only if its collider changes), the pose on
/// every recorded step (static ones only when moved), and a clear when the body goes away; and,
/// if asked, their hierarchies' first levels.
pub(super) fn record_meshes(
    rec: Res<RerunRecording>,
    stats: Res<PhysicsStats>,
    bodies: Query<MeshBody>,
    mut removed: RemovedComponents<Collider>,
    mut logged: ResMut<LoggedMeshes>,
) {
    let stream = &rec.stream;
    set_time(stream, &stats);
    let mut statics_changed = false;
    for entity in removed.read() {
        if let Some((path, _)) = logged.0.remove(&entity) {
            report(stream.log(path, &rerun::Clear::recursive()));
            statics_changed = true;
        }
    }
    for (entity, collider, g, is_static, mass, own_tint, (asleep, sleep)) in &bodies {
        let Shape::TriMesh(mesh) = &collider.shape else {
            if let Some((path, _)) = logged.0.remove(&entity) {
                report(stream.log(path, &rerun::Clear::recursive()));
                statics_changed = true;
            }
            continue;
        };
        let fresh = collider.is_changed() || !logged.0.contains_key(&entity);
        let (path, drawn) = logged
            .0
            .entry(entity)
            .or_insert_with(|| (mesh_path(mesh, entity), [0; 3]));
        // As the other bodies: a sleeping mesh takes its island's muted colour.
        let tint = match (asleep, own_tint) {
            (true, _) => sleeping_color(sleep.map_or(0, |s| s.island)),
            (false, Some(t)) => t.0,
            (false, None) => kind_tint(is_static, mass),
        };
        if fresh {
            log_mesh(stream, path, mesh, tint);
        } else if tint != *drawn {
            let albedo = rerun::datatypes::Rgba32::from_rgb(tint[0], tint[1], tint[2]);
            let recolored = rerun::Mesh3D::update_fields().with_albedo_factor(albedo);
            report(stream.log(path.as_str(), &recolored));
        }
        *drawn = tint;
        let moved = fresh || g.is_changed();
        if moved || !is_static {
            let pose = rerun::Transform3D::from_translation_rotation(
                arr(g.0.translation),
                quat(g.0.rotation),
            );
            report(stream.log(path.as_str(), &pose));
        }
        statics_changed |= is_static && moved;
    }
    let levels = rec.config.bvh_levels as usize;
    if levels > 0 {
        let mut moving = LevelBoxes::new(levels);
        let mut fixed = LevelBoxes::new(levels);
        for (_, collider, g, is_static, ..) in &bodies {
            if let Shape::TriMesh(mesh) = &collider.shape {
                let batch = if is_static { &mut fixed } else { &mut moving };
                batch.add(mesh, &g.0);
            }
        }
        moving.log(stream, "moving");
        if statics_changed {
            fixed.log(stream, "static");
        }
    }
}

/// `world/meshes/<name>_<entity>`, the name reduced to characters safe in an entity path.
fn mesh_path(mesh: &MeshCollider, entity: Entity) -> String {
    let name: String = mesh
        .name()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("world/meshes/{name}_{entity}")
}

/// The mesh's triangles, with smooth normals for shading.
fn log_mesh(stream: &RecordingStream, path: &str, mesh: &MeshCollider, tint: [u8; 3]) {
    let m = mesh.mesh();
    let albedo = rerun::datatypes::Rgba32::from_rgb(tint[0], tint[1], tint[2]);
    let triangles = rerun::Mesh3D::new(m.vertices().iter().map(|v| arr(*v)))
        .with_triangle_indices(m.triangles().iter().copied())
        .with_vertex_normals(vertex_normals(m).into_iter().map(arr))
        .with_albedo_factor(albedo);
    report(stream.log(path, &triangles));
}

/// Area-weighted vertex normals (zero for a vertex no triangle uses).
fn vertex_normals(mesh: &crate::geometry::TriMesh) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; mesh.vertex_count()];
    for (t, corners) in mesh.iter_triangles().zip(mesh.triangles()) {
        let n = t.scaled_normal();
        for &i in corners {
            normals[i as usize] += n;
        }
    }
    normals
        .into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::ZERO))
        .collect()
}

/// World-space OBBs of the first levels of some hierarchies, one batch per level.
struct LevelBoxes {
    centers: Vec<Vec<[f32; 3]>>,
    halves: Vec<Vec<[f32; 3]>>,
    rotations: Vec<Vec<rerun::Quaternion>>,
    /// Node indices of the level being expanded, and of the next (reused buffers).
    frontier: Vec<u32>,
    next: Vec<u32>,
}

impl LevelBoxes {
    fn new(levels: usize) -> Self {
        Self {
            centers: vec![Vec::new(); levels],
            halves: vec![Vec::new(); levels],
            rotations: vec![Vec::new(); levels],
            frontier: Vec::new(),
            next: Vec::new(),
        }
    }

    /// Adds the nodes of `mesh`'s hierarchy at depths below the level count (root: level 0),
    /// placed by `pose`; a leaf ends its branch.
    fn add(&mut self, mesh: &MeshCollider, pose: &crate::geometry::Isometry) {
        let nodes = mesh.bvh().nodes();
        self.frontier.clear();
        self.frontier.push(0);
        for level in 0..self.centers.len() {
            self.next.clear();
            for &i in &self.frontier {
                let Some(node) = nodes.get(i as usize) else {
                    continue;
                };
                self.centers[level].push(arr(pose.transform_point(node.bv.center)));
                self.halves[level].push(arr(node.bv.half_extents));
                self.rotations[level].push(quat(pose.rotation * Quat::from_mat3(&node.bv.axes)));
                if let Some(children) = node.children() {
                    self.next.extend(children);
                }
            }
            std::mem::swap(&mut self.frontier, &mut self.next);
        }
    }

    /// Logs level `k` at `hierarchy/level_<k>/<group>`.
    fn log(self, stream: &RecordingStream, group: &str) {
        let levels = self
            .centers
            .into_iter()
            .zip(self.halves)
            .zip(self.rotations);
        for (k, ((centers, halves), rotations)) in levels.enumerate() {
            let boxes = rerun::Boxes3D::from_centers_and_half_sizes(centers, halves)
                .with_quaternions(rotations)
                .with_colors([color(LEVELS[k % LEVELS.len()])]);
            report(stream.log(format!("hierarchy/level_{k}/{group}"), &boxes));
        }
    }
}

/// The leaves of each mesh contact: their triangles (world space, as closed outlines) and their
/// boxes, first body's cyan, second body's pink.
pub(super) fn record_overlapping_leaves(
    rec: Res<RerunRecording>,
    leaves: Res<OverlappingLeaves>,
    colliders: Query<(&Collider, &GlobalPose)>,
) {
    if !rec.config.overlapping_leaves {
        return;
    }
    let mut strips: Vec<[[f32; 3]; 4]> = Vec::new();
    let mut strip_colors = Vec::new();
    let (mut centers, mut halves, mut rotations, mut box_colors) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut side_leaves = Vec::new();
    for overlap in &leaves.pairs {
        for (side, entity, tint) in [(0, overlap.a, LEAF_A), (1, overlap.b, LEAF_B)] {
            let Ok((c, g)) = colliders.get(entity) else {
                continue;
            };
            let Shape::TriMesh(mesh) = &c.shape else {
                continue;
            };
            side_leaves.clear();
            side_leaves.extend(
                overlap
                    .leaves
                    .iter()
                    .map(|l| l[side])
                    .filter(|&l| l != NO_LEAF),
            );
            side_leaves.sort_unstable();
            side_leaves.dedup();
            let pose = g.0;
            for &leaf in &side_leaves {
                let Some(node) = mesh.bvh().nodes().get(leaf as usize) else {
                    continue;
                };
                for &t in mesh.bvh().leaf_triangles(node) {
                    if let Some(tri) = mesh.mesh().triangle(t as usize) {
                        let [a, b, c] = tri.vertices().map(|v| arr(pose.transform_point(v)));
                        strips.push([a, b, c, a]);
                        strip_colors.push(color(tint));
                    }
                }
                centers.push(arr(pose.transform_point(node.bv.center)));
                halves.push(arr(node.bv.half_extents));
                rotations.push(quat(pose.rotation * Quat::from_mat3(&node.bv.axes)));
                box_colors.push(color(tint));
            }
        }
    }
    let lines = rerun::LineStrips3D::new(strips).with_colors(strip_colors);
    report(rec.stream.log("narrow_phase/overlapping_leaves", &lines));
    let boxes = rerun::Boxes3D::from_centers_and_half_sizes(centers, halves)
        .with_quaternions(rotations)
        .with_colors(box_colors);
    report(
        rec.stream
            .log("narrow_phase/overlapping_leaf_boxes", &boxes),
    );
}
