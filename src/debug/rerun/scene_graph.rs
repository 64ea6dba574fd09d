//! The scene graph as the bounding-volume hierarchy (the slides' "Conclusioni"): the volumes of
//! every body hierarchy level by level, and the nodes the narrow phase's descent entered and
//! pruned.

use super::{LEVELS, RerunRecording, arr, color, report};
use crate::bounding::Aabb;
use crate::components::*;
use crate::plugins::narrow_phase::HierarchyVisits;
use bevy_ecs::name::Name;
use bevy_ecs::prelude::*;

const ENTERED: [u8; 3] = [241, 196, 15];
const PRUNED: [u8; 3] = [127, 140, 141];
const COLLIDER_PAIR: [u8; 3] = [231, 76, 60];

/// Roots of hierarchies: bodies with parts and no parent.
type HierarchyRoot = (With<Children>, Without<ChildOf>, Without<Quarantined>);

type SceneNode<'a> = (&'a BoundingVolume, Option<&'a Children>, Option<&'a Name>);

/// Boxes of one level, with labels (empty for unnamed nodes).
#[derive(Default, Clone)]
struct Level {
    boxes: Vec<Aabb>,
    labels: Vec<String>,
}

/// Logs `scene_graph/level_<k>`: the volume of every node at depth `k` of every hierarchy
/// (each bounds the node's collider and its whole subtree), labelled with the node's [`Name`].
/// Nodes with nothing to collide below them (an empty volume) are left out.
pub(super) fn record_scene_graph_levels(
    rec: Res<RerunRecording>,
    roots: Query<Entity, HierarchyRoot>,
    nodes: Query<SceneNode>,
    mut frontier: Local<(Vec<Entity>, Vec<Entity>)>,
) {
    let depth = rec.config.scene_graph_levels as usize;
    if depth == 0 {
        return;
    }
    let mut levels = vec![Level::default(); depth];
    let (current, next) = &mut *frontier;
    current.clear();
    current.extend(roots.iter());
    current.sort_unstable();
    for level in &mut levels {
        next.clear();
        for &e in current.iter() {
            let Ok((bv, children, name)) = nodes.get(e) else {
                continue;
            };
            if bv.0.is_valid() && bv.0.is_finite() {
                level.boxes.push(bv.0);
                level
                    .labels
                    .push(name.map_or(String::new(), |n| n.as_str().to_owned()));
            }
            next.extend(children.into_iter().flat_map(|c| c.iter()));
        }
        std::mem::swap(current, next);
    }
    for (k, level) in levels.into_iter().enumerate() {
        let mut boxes = boxes_of(&level.boxes).with_colors([color(LEVELS[k % LEVELS.len()])]);
        if level.labels.iter().any(|l| !l.is_empty()) {
            boxes = boxes.with_labels(level.labels).with_show_labels(true);
        }
        report(rec.stream.log(format!("scene_graph/level_{k}"), &boxes));
    }
}

/// Logs `scene_graph/visited/{entered,pruned}` (the nodes' volumes when the descent met them)
/// and `scene_graph/visited/collider_pairs` (segments between the colliders handed to the
/// exact test).
pub(super) fn record_hierarchy_visits(
    rec: Res<RerunRecording>,
    visits: Res<HierarchyVisits>,
    poses: Query<&GlobalPose>,
) {
    if !rec.config.hierarchy_visits {
        return;
    }
    let stream = &rec.stream;
    let volumes = |nodes: &[(Entity, Aabb)]| nodes.iter().map(|(_, b)| *b).collect::<Vec<_>>();
    let entered = boxes_of(&volumes(&visits.entered)).with_colors([color(ENTERED)]);
    report(stream.log("scene_graph/visited/entered", &entered));
    let pruned = boxes_of(&volumes(&visits.pruned)).with_colors([color(PRUNED)]);
    report(stream.log("scene_graph/visited/pruned", &pruned));
    let segments: Vec<[[f32; 3]; 2]> = visits
        .collider_pairs
        .iter()
        .filter_map(|&(a, b)| {
            let (pa, pb) = (poses.get(a).ok()?, poses.get(b).ok()?);
            Some([arr(pa.0.translation), arr(pb.0.translation)])
        })
        .collect();
    let lines = rerun::LineStrips3D::new(segments)
        .with_colors([color(COLLIDER_PAIR)])
        .with_radii([rerun::Radius::new_ui_points(2.0)]);
    report(stream.log("scene_graph/visited/collider_pairs", &lines));
}

fn boxes_of(boxes: &[Aabb]) -> rerun::Boxes3D {
    rerun::Boxes3D::from_centers_and_half_sizes(
        boxes.iter().map(|b| arr(b.center())),
        boxes.iter().map(|b| arr(b.half_extents())),
    )
}
