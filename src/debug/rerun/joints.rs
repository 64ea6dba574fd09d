//! Joints in the recording: each joint's anchors and the segment between them, its axis at A's
//! anchor, in orange (red while its coordinate is past a limit, grey once disabled or broken),
//! and what the joints hold as time series.

use super::{RerunRecording, arr, color, report};
use crate::components::*;
use crate::geometry::Isometry;
use bevy_ecs::prelude::*;
use glam::Vec3;

const HOLDING: [u8; 3] = [230, 126, 34];
const PAST_LIMIT: [u8; 3] = [231, 76, 60];
const DISABLED: [u8; 3] = [127, 140, 141];
/// Length of the drawn axis (m).
const AXIS: f32 = 0.3;
/// Joints with a time series of their own (a 10,000-joint grid would drown the viewer).
const SERIES: usize = 16;

type JointView<'a> = (
    Entity,
    &'a Joint,
    Option<&'a JointLoad>,
    Has<JointDisabled>,
    Has<Quarantined>,
);

/// Logs `world/joints` (anchors, segments, axes) and `joints/<entity>/{force,torque}` (and
/// `motor` for a motorised joint) for the first joints, plus `joints/past_limit` (how far the worst joint is past its limit).
pub(super) fn record_joints(
    rec: Res<RerunRecording>,
    joints: Query<JointView>,
    poses: Query<&GlobalPose>,
) {
    if joints.is_empty() {
        return;
    }
    let stream = &rec.stream;
    let (mut segments, mut colors, mut points) = (Vec::new(), Vec::new(), Vec::new());
    let (mut origins, mut axes) = (Vec::new(), Vec::new());
    let mut worst = 0.0f32;
    for (i, (e, joint, load, disabled, quarantined)) in joints.iter().enumerate() {
        let Some((frame_a, frame_b)) = world_frames(joint, &poses) else {
            continue;
        };
        let (a, b) = (frame_a.translation, frame_b.translation);
        let past = joint.past_limit(&frame_a, &frame_b);
        worst = worst.max(past);
        let hue = if disabled || quarantined {
            DISABLED
        } else if past > 1e-3 {
            PAST_LIMIT
        } else {
            HOLDING
        };
        segments.push([arr(a), arr(b)]);
        colors.push(color(hue));
        points.extend([arr(a), arr(b)]);
        origins.push(arr(a));
        axes.push(arr(frame_a.rotation * Vec3::X * AXIS));
        if let Some(load) = load.filter(|_| i < SERIES) {
            let path = format!("joints/{e}");
            report(stream.log(format!("{path}/force"), &rerun::Scalars::single(load.force)));
            report(stream.log(
                format!("{path}/torque"),
                &rerun::Scalars::single(load.torque),
            ));
            if joint.kind.limit_and_motor().1.is_some() {
                report(stream.log(format!("{path}/motor"), &rerun::Scalars::single(load.motor)));
            }
        }
    }
    let lines = rerun::LineStrips3D::new(segments).with_colors(colors);
    report(stream.log("world/joints/links", &lines));
    report(stream.log(
        "world/joints/anchors",
        &rerun::Points3D::new(points).with_radii([0.03]),
    ));
    let arrows = rerun::Arrows3D::from_vectors(axes)
        .with_origins(origins)
        .with_colors([color(HOLDING)]);
    report(stream.log("world/joints/axes", &arrows));
    report(stream.log("joints/past_limit", &rerun::Scalars::single(worst)));
}

/// The joint's frame on each end in world coordinates, if its bodies are placed.
fn world_frames(joint: &Joint, poses: &Query<&GlobalPose>) -> Option<(Isometry, Isometry)> {
    let a = poses.get(joint.body_a).ok()?.0;
    let b = match joint.body_b {
        JointEnd::Body(b) => Some(poses.get(b).ok()?.0),
        JointEnd::World => None,
    };
    let frames = joint.world_frames(a, b);
    (frames.0.translation.is_finite() && frames.1.translation.is_finite()).then_some(frames)
}
