//! Spheres, ellipsoids, boxes, capsules, cylinders, hulls and half-spaces of one group of bodies
//! gathered into one batch per rerun archetype (`Ellipsoids3D`, `Boxes3D`, `Capsules3D`,
//! `Cylinders3D`, and `LineStrips3D` for the hulls' face outlines), so a step logs five entities
//! however many bodies it draws.

use super::{arr, quat, report};
use crate::geometry::Shape;
use bevy_ecs::name::Name;
use glam::{Quat, Vec3};
use rerun::RecordingStream;

/// Spheres and boxes of one group of bodies, ready to log, with their labels (empty for
/// unnamed bodies; none at all when no body is named).
#[derive(Default)]
pub(super) struct ShapeBatch {
    sphere_centers: Vec<[f32; 3]>,
    sphere_half_sizes: Vec<[f32; 3]>,
    sphere_rotations: Vec<rerun::Quaternion>,
    sphere_colors: Vec<rerun::Color>,
    sphere_labels: Vec<String>,
    box_centers: Vec<[f32; 3]>,
    box_half_sizes: Vec<[f32; 3]>,
    box_rotations: Vec<rerun::Quaternion>,
    box_colors: Vec<rerun::Color>,
    box_labels: Vec<String>,
    capsules: CapsuleBatch,
    cylinders: CapsuleBatch,
    hull_strips: Vec<Vec<[f32; 3]>>,
    hull_colors: Vec<rerun::Color>,
    named: bool,
}

/// Capsules as rerun draws them (from the bottom cap's centre along the rotated +z), or
/// cylinders (from their centres).
#[derive(Default)]
struct CapsuleBatch {
    bottoms: Vec<[f32; 3]>,
    lengths: Vec<f32>,
    radii: Vec<f32>,
    rotations: Vec<rerun::Quaternion>,
    colors: Vec<rerun::Color>,
    labels: Vec<String>,
}

impl ShapeBatch {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn push(
        &mut self,
        shape: &Shape,
        p: Vec3,
        r: Quat,
        color: [u8; 3],
        label: Option<&Name>,
        plane_half_size: f32,
    ) {
        let color = rerun::Color::from_rgb(color[0], color[1], color[2]);
        let label = label.map_or(String::new(), |n| n.as_str().to_owned());
        self.named |= !label.is_empty();
        match shape {
            Shape::Sphere(s) => self.push_ellipsoid(p, Vec3::splat(s.radius), r, color, label),
            Shape::Ellipsoid(e) => self.push_ellipsoid(p, e.radii, r, color, label),
            Shape::Cuboid(c) => self.push_box(p, c.half_extents, r, color, label),
            Shape::Capsule(c) => {
                let batch = &mut self.capsules;
                batch.bottoms.push(arr(p - r * Vec3::Z * c.half_length));
                batch.lengths.push(2.0 * c.half_length);
                batch.radii.push(c.radius);
                batch.rotations.push(quat(r));
                batch.colors.push(color);
                batch.labels.push(label);
            }
            Shape::HalfSpace(h) => {
                // A thin square slab just below the plane, facing along the normal.
                let normal = r * h.normal;
                let facing = Quat::from_rotation_arc(Vec3::Z, normal);
                let half = Vec3::new(plane_half_size, plane_half_size, 0.005);
                self.push_box(p - normal * 0.005, half, facing, color, label);
            }
            // Meshes have their own entities (`record_meshes`).
            Shape::TriMesh(_) => {}
            Shape::Cylinder(c) => {
                let batch = &mut self.cylinders;
                batch.bottoms.push(arr(p));
                batch.lengths.push(2.0 * c.half_height);
                batch.radii.push(c.radius);
                batch.rotations.push(quat(r));
                batch.colors.push(color);
                batch.labels.push(label);
            }
            Shape::Cone(c) => {
                // No cone primitive in rerun: the base's circle and four lines to the apex,
                // drawn as a hull's outline is.
                let at = |v: Vec3| arr(p + r * v);
                let apex = Vec3::Z * c.half_height;
                let rim = |k: usize| {
                    let turn = std::f32::consts::TAU * k as f32 / 24.0;
                    Vec3::new(turn.cos(), turn.sin(), 0.0) * c.radius - apex
                };
                self.hull_strips
                    .push((0..=24).map(|k| at(rim(k))).collect());
                self.hull_colors.push(color);
                for k in [0, 6, 12, 18] {
                    self.hull_strips.push(vec![at(rim(k)), at(apex)]);
                    self.hull_colors.push(color);
                }
            }
            Shape::ConvexHull(h) => {
                for face in 0..h.faces().len() {
                    let mut strip: Vec<[f32; 3]> =
                        h.face_polygon(face).map(|v| arr(p + r * v)).collect();
                    if let Some(&first) = strip.first() {
                        strip.push(first);
                    }
                    self.hull_strips.push(strip);
                    self.hull_colors.push(color);
                }
            }
        }
    }

    fn push_ellipsoid(&mut self, p: Vec3, half: Vec3, r: Quat, color: rerun::Color, label: String) {
        self.sphere_centers.push(arr(p));
        self.sphere_half_sizes.push(arr(half));
        self.sphere_rotations.push(quat(r));
        self.sphere_colors.push(color);
        self.sphere_labels.push(label);
    }

    fn push_box(&mut self, p: Vec3, half: Vec3, r: Quat, color: rerun::Color, label: String) {
        self.box_centers.push(arr(p));
        self.box_half_sizes.push(arr(half));
        self.box_rotations.push(quat(r));
        self.box_colors.push(color);
        self.box_labels.push(label);
    }

    pub(super) fn log(self, rec: &RecordingStream, path: &str) {
        let mut spheres = rerun::Ellipsoids3D::from_centers_and_half_sizes(
            self.sphere_centers,
            self.sphere_half_sizes,
        )
        .with_quaternions(self.sphere_rotations)
        .with_colors(self.sphere_colors)
        .with_fill_mode(rerun::FillMode::Solid);
        let mut boxes =
            rerun::Boxes3D::from_centers_and_half_sizes(self.box_centers, self.box_half_sizes)
                .with_quaternions(self.box_rotations)
                .with_colors(self.box_colors)
                .with_fill_mode(rerun::FillMode::Solid);
        let c = self.capsules;
        let mut capsules = rerun::Capsules3D::from_lengths_and_radii(c.lengths, c.radii)
            .with_translations(c.bottoms)
            .with_quaternions(c.rotations)
            .with_colors(c.colors)
            .with_fill_mode(rerun::FillMode::Solid);
        let y = self.cylinders;
        let mut cylinders = rerun::Cylinders3D::from_lengths_and_radii(y.lengths, y.radii)
            .with_centers(y.bottoms)
            .with_quaternions(y.rotations)
            .with_colors(y.colors)
            .with_fill_mode(rerun::FillMode::Solid);
        let hulls = rerun::LineStrips3D::new(self.hull_strips).with_colors(self.hull_colors);
        if self.named {
            cylinders = cylinders.with_labels(y.labels).with_show_labels(true);
            spheres = spheres
                .with_labels(self.sphere_labels)
                .with_show_labels(true);
            boxes = boxes.with_labels(self.box_labels).with_show_labels(true);
            capsules = capsules.with_labels(c.labels).with_show_labels(true);
        }
        report(rec.log(format!("{path}/spheres"), &spheres));
        report(rec.log(format!("{path}/boxes"), &boxes));
        report(rec.log(format!("{path}/capsules"), &capsules));
        report(rec.log(format!("{path}/cylinders"), &cylinders));
        report(rec.log(format!("{path}/hulls"), &hulls));
    }
}
