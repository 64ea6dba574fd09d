//! Speculative contacts: pairs found while still apart by up to a margin, with their
//! separations as negative depths, so that a solver that detects once per step can stop a body at the surface
//! before it gets there (Catto, "Speculative Contacts", 2013; Box2D's 2 cm speculative
//! distance).
//!
//! The closed-form tests report only touching or penetrating pairs, so one of the two shapes is
//! tested grown by the margin and each point's separation is the margin minus its depth against
//! the grown shape. A ball or a capsule, which grow exactly (their radius), is the shape grown
//! if the pair has one; then a box, by its half extents: exact across faces, early near edges
//! and corners (a grown box is not a rounded one), which only makes a contact speculative
//! sooner, while a pair that reads penetrating is also measured on the true shapes, never
//! deeper ([`grown_box_contact`]); then a half-space, whose boundary moves out (exact). A box
//! on the ground is read with the box grown: raising the plane instead (exact for a tilted
//! box) let the accuracy report's 20-box stack sway 10.0 mm in 10 s against 5.6 mm. Two meshes are not grown:
//! their hierarchies are descended with boxes grown by the margin, and triangle pairs that do
//! not cross report their exact gap (`trimesh_trimesh.rs`).

use super::{
    ContactScratch, contact_trimesh_trimesh_within, contact_with_scratch, general_convex_contact,
};
use crate::geometry::{
    Capsule, ContactManifold, ContactPoint, Cuboid, Isometry, Shape, Sphere, length_or_zero,
};
use glam::Vec3;

/// The shape grown exactly by `margin` (a ball's or a capsule's radius), or `None`.
fn rounded_grown(shape: &Shape, margin: f32) -> Option<Shape> {
    match shape {
        Shape::Sphere(s) => Some(Shape::Sphere(Sphere {
            radius: s.radius + margin,
        })),
        Shape::Capsule(c) => Some(Shape::Capsule(Capsule {
            radius: c.radius + margin,
            ..*c
        })),
        _ => None,
    }
}

/// The manifold of a grown shape brought back to the true surfaces: the grown surface of A
/// lies `added` further along the normal (of B, `added` back), so the midpoint moved by half of
/// it, and each depth shrinks by `added` (negative: still apart). A grown box (`rim`) is not a
/// rounded one: a point on its grown edge or corner stands `(|n·x| + |n·y| + |n·z|) added`
/// out along the normal from the true edge or corner it grew from (up to `√3 added`), so its
/// depth shrinks by that, measured ([`grown_box_excess`], less [`RIM_EXCESS_SLACK`]); read as
/// `added`, a cube landing on an edge saw 41 % of the margin as contact and came to rest that
/// far above the floor (the fourth probe: up to 3.9 mm). The point is then pulled in across
/// the normal to the true box, or the lever arms would be `added` too long.
fn from_grown(
    m: ContactManifold,
    added: f32,
    rim: Option<(&Cuboid, &Isometry)>,
    grown_a: bool,
) -> ContactManifold {
    let shift = m.normal * (if grown_a { -0.5 } else { 0.5 } * added);
    let mut out = ContactManifold::new(m.normal);
    for p in m.points() {
        let mut point = p.point + shift;
        let mut excess = added;
        if let Some((c, pose)) = rim {
            let beyond = grown_box_excess(p, m.normal, (c, pose), grown_a) - added;
            excess += (beyond - RIM_EXCESS_SLACK * added).max(0.0);
            let local = pose.inverse_transform_point(point);
            let inside = local.clamp(-c.half_extents, c.half_extents);
            let pulled = pose.transform_point(inside);
            // Keep the offset along the normal; remove only the part across it.
            let off = point - pulled;
            point = pulled + m.normal * off.dot(m.normal);
        }
        out.push(ContactPoint {
            point,
            depth: p.depth - excess,
            ..*p
        });
    }
    out
}

/// How far out along its outward normal the grown box's surface point of `p` stands from the
/// true box: `added` on a face met square on, more on a grown edge or corner. The grown
/// surface point is half the depth from the midpoint `p.point` (towards B when the box is A);
/// the true box's point it grew from is its clamp into the true box.
fn grown_box_excess(
    p: &ContactPoint,
    normal: Vec3,
    (c, pose): (&Cuboid, &Isometry),
    grown_a: bool,
) -> f32 {
    let outward = if grown_a { normal } else { -normal };
    let surface = p.point + outward * (0.5 * p.depth);
    let local = pose.inverse_transform_point(surface);
    let grew_from = pose.transform_point(local.clamp(-c.half_extents, c.half_extents));
    (surface - grew_from).dot(outward)
}

/// The contact of `a` and `b` with a speculative `margin` (see the module doc), or `None` when
/// they are farther apart than the margin. Depths are signed: a point still `d` apart has depth
/// `-d`. Allocates for meshes; see [`speculative_contact_with_scratch`].
pub fn speculative_contact(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    margin: f32,
) -> Option<ContactManifold> {
    speculative_contact_with_scratch(a, pose_a, b, pose_b, margin, &mut ContactScratch::new())
}

/// [`speculative_contact`] with caller-owned buffers (as
/// [`contact_with_scratch`]).
pub fn speculative_contact_with_scratch(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    margin: f32,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    if margin > 0.0 && margin.is_finite() {
        // Cylinders, ellipsoids and hulls measure their gap directly (GJK): exact.
        if let Some(m) = general_convex_contact(a, pose_a, b, pose_b, margin, scratch) {
            return m;
        }
        if let (Shape::TriMesh(ma), Shape::TriMesh(mb)) = (a, b) {
            return contact_trimesh_trimesh_within(pose_a, ma, pose_b, mb, margin, scratch);
        }
        // Exact growth first: a ball's or a capsule's radius.
        if let Some(ga) = rounded_grown(a, margin) {
            let m = contact_with_scratch(&ga, pose_a, b, pose_b, scratch)?;
            return Some(from_grown(m, margin, None, true));
        }
        if let Some(gb) = rounded_grown(b, margin) {
            let m = contact_with_scratch(a, pose_a, &gb, pose_b, scratch)?;
            return Some(from_grown(m, margin, None, false));
        }
        if let Shape::Cuboid(c) = a {
            return grown_box_contact((c, pose_a, true), (a, pose_a, b, pose_b), margin, scratch);
        }
        if let Shape::Cuboid(c) = b {
            return grown_box_contact((c, pose_b, false), (a, pose_a, b, pose_b), margin, scratch);
        }
        // A half-space grows by moving its boundary out (exact): a mesh above the ground is
        // found.
        if let Some(raised) = raised_half_space(a, pose_a, margin) {
            let m = contact_with_scratch(a, &raised, b, pose_b, scratch)?;
            return Some(from_grown(m, margin, None, true));
        }
        if let Some(raised) = raised_half_space(b, pose_b, margin) {
            let m = contact_with_scratch(a, pose_a, b, &raised, scratch)?;
            return Some(from_grown(m, margin, None, false));
        }
    }
    contact_with_scratch(a, pose_a, b, pose_b, scratch)
}

/// The speculative contact of a pair one of whose shapes is the box `c` (`grown_a`: it is `a`),
/// found with the box grown by `margin` in each half extent. A grown box is not a rounded one:
/// its edges and corners stand out by up to `(|n·x| + |n·y| + |n·z| − 1) · margin` more than its
/// faces along a direction `n` (x, y, z its axes), which makes a pair still apart speculative
/// sooner, but also biases the separating-axis choice and reads a penetrating pair deeper than
/// it is, by up to `(√3 − 1) · margin`. A solver pushes that depth out: in the `avalanche`
/// example a capsule 5.8 cm into a box read 9.1 cm with the box grown by 12 cm, and the box was
/// flung off at 4 m/s (a ball or a capsule is now the shape grown, exactly), and two crossing
/// boxes read 2.4 cm too deep with a 27 cm margin. So a pair the grown box finds penetrating
/// is measured on the true shapes too, and no point is kept deeper than they are; points still
/// apart keep their speculative separations, so a resting box keeps all its corners. The grown
/// manifold's normal is kept: handing over the true shapes' manifold instead (their normal and
/// points) was tried and lost the speculative corners of loaded boxes (a 100:1 heavy box on a
/// light one, a box sliding over a tessellated floor both failed their bounds), so a biased
/// axis may remain, pushed no deeper than the truth. The price is a second test for
/// penetrating grown-box pairs that the manifold cache does not answer.
fn grown_box_contact(
    (c, pose, grown_a): (&Cuboid, &Isometry, bool),
    (a, pose_a, b, pose_b): (&Shape, &Isometry, &Shape, &Isometry),
    margin: f32,
    scratch: &mut ContactScratch,
) -> Option<ContactManifold> {
    let grown = Shape::Cuboid(Cuboid {
        half_extents: c.half_extents + margin,
    });
    let m = if grown_a {
        contact_with_scratch(&grown, pose_a, b, pose_b, scratch)?
    } else {
        contact_with_scratch(a, pose_a, &grown, pose_b, scratch)?
    };
    let m = from_grown(m, margin, Some((c, pose)), grown_a);
    if m.max_depth() <= 0.0 {
        return Some(m);
    }
    let truth = contact_with_scratch(a, pose_a, b, pose_b, scratch).map_or(0.0, |t| t.max_depth());
    if m.max_depth() <= truth + MAX_GROWN_BOX_ERROR {
        return Some(m);
    }
    let mut capped = ContactManifold::new(m.normal);
    for p in m.points() {
        capped.push(ContactPoint {
            depth: p.depth.min(truth),
            ..*p
        });
    }
    Some(capped)
}

/// The share of the margin by which a grown box's point may stand out beyond its face's
/// reading and still be read as the face (see [`from_grown`]): a face tilted by less than
/// about 0.6° (`cos θ + sin θ − 1` below it) keeps the face's reading exactly, and a point on
/// a grown edge or corner reads its true gap within this share of the margin. Measured to
/// the full excess, the rounding of points metres up and the tilts of a resting stack came
/// into every reading: the 20-box stack's drift went from 0.81 to 2.2 cm in 10 s.
const RIM_EXCESS_SLACK: f32 = 0.01;

/// How much deeper than the true shapes a grown box's contact may read before its points are
/// capped (m).
const MAX_GROWN_BOX_ERROR: f32 = 1e-5;

/// How far a body can move in `dt`, for its speculative margin: its centre at `speed` plus
/// the exact fall `a dt²/2`, and its surface turning at `angular_speed` times its `reach` (the
/// radius about its centre that holds it). A body integrated in symplectic Euler substeps falls
/// up to twice as far in `dt` (`(n + 1) / n` times as far over `n` substeps): the solver's
/// lookahead passes `a (n + 1) / n`. Non-finite inputs count as no motion (validation
/// quarantines such bodies).
pub fn motion_bound(speed: f32, angular_speed: f32, reach: f32, acceleration: f32, dt: f32) -> f32 {
    length_or_zero(raw_motion_bound(
        speed + angular_speed * reach,
        acceleration,
        dt,
    ))
}

/// [`motion_bound`] of a point at `speed` as computed, infinite or NaN when the inputs are (a
/// caller that must not read an overflow as no motion decides what it means).
pub fn raw_motion_bound(speed: f32, acceleration: f32, dt: f32) -> f32 {
    speed * dt + 0.5 * acceleration * dt * dt
}

/// The pose of a half-space moved `margin` out along its outward normal (`None` for any other
/// shape).
fn raised_half_space(shape: &Shape, pose: &Isometry, margin: f32) -> Option<Isometry> {
    let Shape::HalfSpace(h) = shape else {
        return None;
    };
    let out = pose.rotation * h.normal;
    Some(Isometry::new(
        pose.translation + out * margin,
        pose.rotation,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_speculative_contact_never_reads_deeper_than_the_true_shapes_by_1e_4_whatever_the_margin() {
        // Boxes against balls, capsules, boxes and the ground, in both orders, close enough to
        // touch or cross, with margins up to 30 cm: a grown box's edges and corners stand out,
        // and a penetration read there used to be up to (√3 − 1) × the margin too deep.
        let mut rng = crate::test_rng::TestRng::new(23);
        let others = [
            Shape::sphere(0.2),
            Shape::capsule(0.25, 0.08),
            Shape::cuboid(Vec3::new(0.3, 0.1, 0.2)),
            Shape::half_space(Vec3::Z),
        ];
        let (mut penetrating, mut overstated) = (0, 0);
        for k in 0..4000 {
            let cuboid = Shape::cuboid(rng.vec3(0.1, 0.3));
            let other = &others[k % others.len()];
            let box_pose = Isometry::new(rng.vec3(-0.4, 0.4), rng.rotation());
            let other_pose = Isometry::new(rng.vec3(-0.4, 0.4), rng.rotation());
            let margin = rng.range(0.02, 0.3);
            let ((a, pa), (b, pb)) = if k % 8 < 4 {
                ((&cuboid, box_pose), (other, other_pose))
            } else {
                ((other, other_pose), (&cuboid, box_pose))
            };
            let truth = crate::geometry::contacts::contact(a, &pa, b, &pb).map(|m| m.max_depth());
            let read = speculative_contact(a, &pa, b, &pb, margin).map(|m| m.max_depth());
            let excess = read.unwrap_or(0.0) - truth.unwrap_or(0.0);
            penetrating += usize::from(truth.is_some_and(|d| d > 0.0));
            assert!(
                excess <= 1e-4,
                "{k}: read {read:?}, true {truth:?}, margin {margin}"
            );
            // The box grown by the margin alone, as it was read before: the cases guarded.
            let grown = Shape::cuboid(half_extents_of(&cuboid) + margin);
            let plain = crate::geometry::contacts::contact(&grown, &box_pose, other, &other_pose)
                .map_or(0.0, |m| m.max_depth() - margin);
            overstated += usize::from(plain > truth.unwrap_or(0.0) + 1e-3);
        }
        assert!(penetrating > 1000, "{penetrating} penetrating pairs");
        assert!(
            overstated > 100,
            "the grown box alone overstated {overstated} depths"
        );
    }

    fn half_extents_of(shape: &Shape) -> Vec3 {
        match shape {
            Shape::Cuboid(c) => c.half_extents,
            _ => Vec3::ZERO,
        }
    }

    #[test]
    fn a_ball_above_the_ground_reports_its_exact_gap() {
        let ground = Shape::half_space(Vec3::Z);
        let ball = Shape::sphere(0.5);
        let at = Isometry::from_translation(Vec3::new(0.0, 0.0, 0.51));
        let c = speculative_contact(&ground, &Isometry::default(), &ball, &at, 0.02).unwrap();
        let p = c.points()[0];
        assert!((p.depth + 0.01).abs() < 1e-6, "{}", p.depth);
        // Midway between the true surfaces (z = 0 and z = 0.01), not the grown ones.
        assert!((p.point.z - 0.005).abs() < 1e-6, "{}", p.point);
        assert!(speculative_contact(&ground, &Isometry::default(), &ball, &at, 0.005).is_none());
    }

    #[test]
    fn a_box_above_the_ground_has_its_points_at_its_true_corners() {
        let ground = Shape::half_space(Vec3::Z);
        let b = Shape::cuboid(Vec3::splat(0.5));
        let at = Isometry::from_translation(Vec3::new(0.0, 0.0, 0.51));
        let c = speculative_contact(&ground, &Isometry::default(), &b, &at, 0.02).unwrap();
        assert_eq!(c.points().len(), 4);
        for p in c.points() {
            assert!((p.point.x.abs() - 0.5).abs() < 1e-5 && (p.point.y.abs() - 0.5).abs() < 1e-5);
            assert!((p.depth + 0.01).abs() < 1e-5);
        }
    }

    #[test]
    fn a_mesh_box_above_the_ground_reports_its_gap_from_the_raised_plane() {
        let ground = Shape::half_space(Vec3::Z);
        let mesh = crate::geometry::TriMesh::cuboid(Vec3::splat(0.5)).unwrap();
        let b = Shape::TriMesh(crate::geometry::MeshCollider::new(mesh).unwrap());
        let at = Isometry::from_translation(Vec3::new(0.0, 0.0, 0.53));
        let c = speculative_contact(&ground, &Isometry::default(), &b, &at, 0.05).unwrap();
        assert!(!c.points().is_empty());
        for p in c.points() {
            assert!((p.depth + 0.03).abs() < 1e-5, "{}", p.depth);
        }
        assert!(speculative_contact(&ground, &Isometry::default(), &b, &at, 0.02).is_none());
    }

    /// A 4 m mesh floor of 8 × 8 cells and a unit mesh box.
    fn mesh_floor_and_box() -> (Shape, Shape) {
        use crate::geometry::{MeshCollider, TriMesh};
        let mesh = |m: TriMesh| Shape::TriMesh(MeshCollider::new(m).unwrap());
        (
            mesh(TriMesh::grid_floor(4.0, 8).unwrap()),
            mesh(TriMesh::cuboid(Vec3::splat(0.5)).unwrap()),
        )
    }

    #[test]
    fn a_mesh_box_above_a_mesh_floor_reports_its_gap_at_its_corners() {
        let (floor, b) = mesh_floor_and_box();
        let at = Isometry::from_translation(Vec3::new(0.1, 0.2, 0.53));
        let c = speculative_contact(&floor, &Isometry::default(), &b, &at, 0.05).unwrap();
        assert!(c.normal.abs_diff_eq(Vec3::Z, 1e-5), "{}", c.normal);
        assert!(c.points().len() >= 3);
        for p in c.points() {
            assert!((p.depth + 0.03).abs() < 1e-5, "{}", p.depth);
            assert!((p.point.z - 0.015).abs() < 1e-5, "{}", p.point);
        }
        // Swapped: the same gap, the normal turned round; beyond the margin: nothing.
        let back = speculative_contact(&b, &at, &floor, &Isometry::default(), 0.05).unwrap();
        assert!(back.normal.abs_diff_eq(-Vec3::Z, 1e-5));
        assert!(speculative_contact(&floor, &Isometry::default(), &b, &at, 0.02).is_none());
    }

    #[test]
    fn bad_margins_and_poses_of_two_meshes_give_the_touching_answer_or_none_never_a_panic() {
        let (floor, b) = mesh_floor_and_box();
        let sunk = Isometry::from_translation(Vec3::new(0.13, 0.21, 0.49));
        let at = Isometry::default();
        let touching = speculative_contact(&floor, &at, &b, &sunk, 0.0);
        assert!(touching.is_some());
        for margin in [f32::NAN, -1.0, f32::NEG_INFINITY, f32::INFINITY] {
            // Not a positive finite number: no lookahead, the touching answer exactly.
            assert_eq!(
                speculative_contact(&floor, &at, &b, &sunk, margin),
                touching
            );
        }
        let nan = Isometry::from_translation(Vec3::new(f32::NAN, 0.0, 0.5));
        for margin in [0.0, 0.05] {
            let _ = speculative_contact(&floor, &at, &b, &nan, margin);
        }
        let mut cache = super::super::ManifoldCache::default();
        cache.begin_step();
        let tested = (touching.as_ref(), super::super::RoundSide::Neither);
        cache.insert((1, 2), (&at, &sunk), 0.0, tested, &[]);
        assert!(
            cache.get((1, 2), (&at, &nan), 1.0, 0.0).is_none(),
            "a NaN pose is never a hit"
        );
        assert!(
            cache.get((1, 2), (&at, &sunk), f32::NAN, 0.0).is_none(),
            "nor a NaN reach"
        );
        assert!(cache.get((1, 2), (&at, &sunk), 1.0, f32::NAN).is_none());
        assert!(cache.get((1, 2), (&at, &sunk), 1.0, 0.0).is_some());
    }

    #[test]
    fn a_box_over_a_box_reports_the_face_gap_at_every_point() {
        let a = Shape::cuboid(Vec3::splat(0.5));
        let b = Shape::cuboid(Vec3::new(0.3, 0.3, 0.2));
        let above = Isometry::from_translation(Vec3::new(0.1, 0.0, 0.5 + 0.2 + 0.015));
        let c = speculative_contact(&a, &Isometry::default(), &b, &above, 0.02).unwrap();
        assert!(c.normal.abs_diff_eq(Vec3::Z, 1e-6));
        assert_eq!(c.points().len(), 4);
        for p in c.points() {
            assert!((p.depth + 0.015).abs() < 1e-5);
            assert!((p.point.z - (0.5 + 0.0075)).abs() < 1e-5, "{}", p.point);
        }
    }

    /// A cube standing on an edge (45°) or a corner, `gap` above the ground, a box and a
    /// second cube: the speculative reading is the true gap at every point, whichever side
    /// is grown, within the slack. Read as the face's `margin`, the edge's gap was short by
    /// 41 % of the margin and a cube came to rest that far above the floor.
    #[test]
    fn a_cube_on_an_edge_or_a_corner_reads_its_true_gap_within_a_hundredth_of_the_margin() {
        let cube = Shape::cuboid(Vec3::splat(0.3));
        let edge = glam::Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
        let corner = glam::Quat::from_rotation_arc(Vec3::ONE.normalize(), -Vec3::Z);
        let grounds = [
            (Shape::half_space(Vec3::Z), Isometry::default()),
            (
                Shape::cuboid(Vec3::new(5.0, 5.0, 0.5)),
                Isometry::from_translation(Vec3::new(0.0, 0.0, -0.5)),
            ),
            (
                Shape::cuboid(Vec3::splat(0.3)),
                Isometry::from_translation(Vec3::new(0.05, -0.02, -0.3)),
            ),
        ];
        for rotation in [edge, corner] {
            let lowest = (0..8)
                .map(|k| {
                    let s = |bit: usize| if k & bit == 0 { -0.3 } else { 0.3 };
                    (rotation * Vec3::new(s(1), s(2), s(4))).z
                })
                .fold(f32::MAX, f32::min);
            for gap in [0.0005, 0.002, 0.01] {
                let at = Isometry::new(Vec3::new(0.0, 0.0, gap - lowest), rotation);
                for (ground, pose) in &grounds {
                    for margin in [0.02, 0.05] {
                        let up = speculative_contact(ground, pose, &cube, &at, margin).unwrap();
                        let down = speculative_contact(&cube, &at, ground, pose, margin).unwrap();
                        for m in [up, down] {
                            let read = m.points().iter().map(|p| -p.depth).fold(f32::MAX, f32::min);
                            let short = gap - read;
                            let slack = RIM_EXCESS_SLACK * margin + 1e-5;
                            assert!((-1e-5..slack).contains(&short), "gap {gap}: read {read}");
                        }
                    }
                }
            }
        }
    }
}
