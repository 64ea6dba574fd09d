//! Joints in the recording: each joint's anchors and the segment between them, its axis at A's
//! anchor, in orange (red while its coordinate is past a limit, grey once disabled or broken),
//! and what the joints hold as time series.

use super::{RerunRecording, arr, color, report};
use crate::components::*;
use crate::dynamics::solver::joint::twist_angle;
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

/// Logs `world/joints` (anchors, segments, axes) and `joints/<entity>/{force,torque}` for the
/// first joints, plus `joints/past_limit` (how far the worst joint is past its limit).
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
        let past = past_limit(joint, &frame_a, &frame_b);
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

/// The joint's frame on each end in world coordinates (anchor and basis).
fn world_frames(joint: &Joint, poses: &Query<&GlobalPose>) -> Option<(Isometry, Isometry)> {
    let frame = |pose: Isometry, anchor: Vec3, basis| {
        Isometry::new(pose.transform_point(anchor), pose.rotation * basis)
    };
    let a = poses.get(joint.body_a).ok()?.0;
    let b = match joint.body_b {
        JointEnd::Body(b) => poses.get(b).ok()?.0,
        JointEnd::World => Isometry::default(),
    };
    let frames = (
        frame(a, joint.anchor_a, joint.basis_a),
        frame(b, joint.anchor_b, joint.basis_b),
    );
    (frames.0.translation.is_finite() && frames.1.translation.is_finite()).then_some(frames)
}

/// How far the joint's coordinate is past its limit (rad or m; 0 within it or without one).
fn past_limit(joint: &Joint, a: &Isometry, b: &Isometry) -> f32 {
    let swing = match joint.kind {
        JointKind::Spherical {
            swing: Some(cone), ..
        } => {
            let (x_a, x_b) = (a.rotation * Vec3::X, b.rotation * Vec3::X);
            (x_a.angle_between(x_b) - cone).max(0.0)
        }
        _ => 0.0,
    };
    let (Some(limit), _) = joint.kind.limit_and_motor() else {
        return swing;
    };
    let coordinate = match joint.kind {
        JointKind::Revolute { .. } | JointKind::Spherical { .. } => {
            twist_angle(a.rotation, b.rotation)
        }
        JointKind::Prismatic { .. } => (a.rotation * Vec3::X).dot(b.translation - a.translation),
        _ => a.translation.distance(b.translation),
    };
    (limit.min - coordinate)
        .max(coordinate - limit.max)
        .max(0.0)
}
