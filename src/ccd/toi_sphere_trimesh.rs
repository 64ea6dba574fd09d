//! Sweep against a triangle mesh through its bounding-volume hierarchy: the earliest impact over
//! the triangles whose leaves the swept sphere may reach.
//!
//! The sweep is carried into the mesh's frame once (the mesh and its BVH never move). The descent
//! ([`Bvh::descend`]) culls each node with the swept sphere's capsule against the node's BV
//! ([`SweepCull`]), and the capsule **shrinks as hits are found**: once a triangle is hit at `t`,
//! only the first `t` of the displacement can give an earlier one. Each candidate triangle runs
//! the exact triangle query ([`toi_sphere_triangle`](super::toi_sphere_triangle)'s pieces).
//!
//! **Faces win near-ties.** A ball landing on a tessellated floor right next to an edge between
//! two triangles enters the face of one and, a rounding error later or *earlier*, the edge
//! cylinder of the other, whose normal is tilted. Hits within the time the sweep takes to travel
//! its tolerance are a tie, and a face hit wins it, so the reported normal is the surface's (the
//! reported `t` may then be later than the earliest by at most that time, i.e. the tolerance in
//! distance).
//!
//! Nothing is allocated per query: the descent's stack lives in the caller's [`QueryScratch`].

use super::toi_sphere_triangle::SweptCentre;
use super::{MeshToi, SphereSweep, SweepCull, Toi};
use crate::bounding::Bv;
use crate::bvh::{Bvh, QueryScratch, QueryStats};
use crate::geometry::{Isometry, TriMesh};
use std::cell::Cell;
use std::ops::ControlFlow;

/// Time of impact of the sweep against `mesh` placed at `pose`, with `bvh` built over the mesh's
/// triangles (`Bvh::build(mesh.vertices(), mesh.triangles(), …)`), and the work the descent did.
///
/// The earliest hit wins, a face hit winning near-ties (see the module notes); among equally
/// early ones, the first in descent order. A contact at the start (`t = 0`, under the sweep's
/// [`InitialOverlap`](super::InitialOverlap) policy) ends the search at once. Triangles are
/// two-sided, so the inside of a closed mesh is not solid: a sphere inside it hits the surface
/// on its way out. A `bvh` built over another mesh gives meaningless results (triangle indices
/// past the mesh's end are skipped, so it does not panic).
pub fn toi_sphere_trimesh<B: Bv + SweepCull>(
    sweep: &SphereSweep,
    mesh: &TriMesh,
    bvh: &Bvh<B>,
    pose: &Isometry,
    scratch: &mut QueryScratch,
) -> (Option<MeshToi>, QueryStats) {
    let local = sweep.in_frame(pose);
    let centre = SweptCentre::of(&local);
    // The culling radius covers the slack the triangle test allows.
    let cull_radius = local.radius() + local.slack();
    let window = face_preference_window(&local);
    let mut best = Best::default();
    let cutoff = Cell::new(1.0f32);
    let stats = bvh.descend(
        scratch,
        |bv| {
            bv.may_touch_sweep(
                local.center(),
                local.displacement(),
                cull_radius,
                cutoff.get(),
            )
        },
        |index| {
            let Some(tri) = mesh.triangle(index as usize) else {
                return ControlFlow::Continue(());
            };
            if let Some(m) = centre.start_contact(&tri) {
                if let Some(toi) = local.initial_contact(m.normal, m.points()[0].point) {
                    best.found = Some((toi, index));
                    return ControlFlow::Break(());
                }
                return ControlFlow::Continue(());
            }
            if let Some(hit) = centre.triangle_entry(&tri, cutoff.get()) {
                // A face hit counts as `window` earlier than it is (see the notes above).
                let rank = if hit.on_face { hit.t - window } else { hit.t };
                if rank < best.rank {
                    best.rank = rank;
                    best.found = Some((local.impact(hit.t, hit.normal), index));
                    cutoff.set((rank + window).min(1.0));
                }
            }
            ControlFlow::Continue(())
        },
    );
    let world = best.found.map(|(toi, triangle)| MeshToi {
        toi: Toi {
            t: toi.t,
            normal: pose.transform_vector(toi.normal),
            point: pose.transform_point(toi.point),
        },
        triangle,
    });
    (world, stats)
}

/// The best hit so far and its rank (its time, less the window for a face hit).
struct Best {
    rank: f32,
    found: Option<(Toi, u32)>,
}

impl Default for Best {
    fn default() -> Self {
        Self {
            rank: f32::INFINITY,
            found: None,
        }
    }
}

/// The time the sweep takes to travel its tolerance: hits closer in time than this are a tie
/// up to rounding, and a face hit wins such a tie.
fn face_preference_window(sweep: &SphereSweep) -> f32 {
    let length = sweep.displacement().length();
    if length > 0.0 {
        (sweep.tolerance() / length).min(1.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::{Aabb, BoundingSphere, Kdop18, Obb};
    use crate::bvh::BuildOptions;
    use crate::ccd::{InitialOverlap, toi_sphere_triangle};
    use glam::{Quat, Vec3};

    fn query<B: Bv + SweepCull>(
        sweep: &SphereSweep,
        mesh: &TriMesh,
        pose: &Isometry,
    ) -> Option<MeshToi> {
        let bvh = Bvh::<B>::build(mesh.vertices(), mesh.triangles(), &BuildOptions::default());
        let mut scratch = QueryScratch::new();
        toi_sphere_trimesh(sweep, mesh, &bvh.unwrap(), pose, &mut scratch).0
    }

    /// The earliest hit over all triangles, without a hierarchy.
    fn brute_force(sweep: &SphereSweep, mesh: &TriMesh, pose: &Isometry) -> Option<(f32, u32)> {
        let local = sweep.in_frame(pose);
        mesh.iter_triangles()
            .enumerate()
            .filter_map(|(i, tri)| toi_sphere_triangle(&local, &tri).map(|toi| (toi.t, i as u32)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    #[test]
    fn agrees_with_the_brute_force_minimum_for_every_bv_kind() {
        let mesh = TriMesh::uv_sphere(1.0, 12, 8).unwrap();
        let pose = Isometry::new(Vec3::new(0.5, -1.0, 2.0), Quat::from_rotation_y(0.6));
        let mut hits = 0;
        for i in 0..300 {
            let angle = i as f32 * 0.37;
            let start =
                pose.translation + Vec3::new(angle.cos(), angle.sin(), (angle * 0.7).sin()) * 3.0;
            let aim =
                pose.translation + Vec3::new((angle * 1.3).sin(), (angle * 2.1).cos(), 0.4) * 0.9;
            let radius = 0.05 + 0.3 * (i % 5) as f32 / 5.0;
            let sweep = SphereSweep::new(start, radius, (aim - start) * 1.2).unwrap();
            let expected = brute_force(&sweep, &mesh, &pose);
            let kinds = [
                query::<Aabb>(&sweep, &mesh, &pose),
                query::<Obb>(&sweep, &mesh, &pose),
                query::<BoundingSphere>(&sweep, &mesh, &pose),
                query::<Kdop18>(&sweep, &mesh, &pose),
            ];
            // Equal up to the face-preference window.
            let window = face_preference_window(&sweep);
            for got in kinds {
                match (got, expected) {
                    (Some(got), Some((t, _))) => {
                        assert!((got.toi.t - t).abs() <= window, "sweep {i}")
                    }
                    (None, None) => {}
                    other => panic!("sweep {i}: {other:?}"),
                }
            }
            hits += usize::from(expected.is_some());
        }
        assert!(hits > 100 && hits < 300, "{hits}");
    }

    #[test]
    fn world_normal_and_point_follow_the_pose_and_a_floor_resting_contact_is_skipped() {
        let floor = TriMesh::grid_floor(10.0, 4).unwrap();
        let pose = Isometry::new(Vec3::new(0.0, 0.0, 1.0), Quat::from_rotation_x(0.2));
        let up = pose.transform_vector(Vec3::Z);
        let start = pose.transform_point(Vec3::new(0.3, 0.2, 2.0));
        let sweep = SphereSweep::new(start, 0.5, -up * 3.0).unwrap();
        let hit = query::<Aabb>(&sweep, &floor, &pose).unwrap();
        assert!((hit.toi.t - 0.5).abs() < 1e-5);
        assert!((hit.toi.normal - up).length() < 1e-5);
        assert!((hit.toi.point - pose.transform_point(Vec3::new(0.3, 0.2, 0.0))).length() < 1e-5);
        // Resting on the floor (sunk 1e-3 into it) and sliding along it: reported at t = 0 by
        // default, skipped with ApproachingOnly.
        let resting = pose.transform_point(Vec3::new(0.3, 0.2, 0.499));
        let slide = SphereSweep::new(resting, 0.5, pose.transform_vector(Vec3::X)).unwrap();
        assert_eq!(query::<Aabb>(&slide, &floor, &pose).unwrap().toi.t, 0.0);
        let slide = slide.with_initial_overlap(InitialOverlap::ApproachingOnly);
        assert!(query::<Aabb>(&slide, &floor, &pose).is_none());
    }

    #[test]
    fn zero_radius_rays_do_not_slip_between_the_triangles_of_a_floor() {
        let floor = TriMesh::grid_floor(4.0, 8).unwrap();
        // Rays aimed at grid vertices and edge midpoints (shared by 2 to 6 triangles).
        for i in 0..=16 {
            for j in 0..=16 {
                let target = Vec3::new(-2.0 + i as f32 * 0.25, -2.0 + j as f32 * 0.25, 0.0);
                let start = target + Vec3::new(0.3, -0.2, 1.0);
                let ray = SphereSweep::new(start, 0.0, Vec3::new(0.3, -0.2, 1.0) * -2.0).unwrap();
                let hit = query::<Aabb>(&ray, &floor, &Isometry::IDENTITY);
                assert!(
                    hit.is_some_and(|h| (h.toi.t - 0.5).abs() < 1e-5),
                    "{target}"
                );
            }
        }
    }
}
