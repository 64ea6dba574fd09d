//! Friction per contact patch: rapier's default friction model (`FrictionModel::Simplified`,
//! `contact_with_twist_friction.rs`) and PhysX's patch friction, as a choice beside the
//! per-point friction of Box2D v3, Jolt and Avian ([`FrictionModel`]).
//!
//! Per point, a face-to-face box contact carries eight friction rows (two tangents at each of
//! four corners). Per patch it carries three, for the same two things a patch resists:
//!
//! - **sliding**: two tangent rows at the patch centre `c` (the mean of the points), the
//!   [`RowPart`]s of [`contact`](super::contact) with anchors `c − x_a`, `c − x_b`; the pair is
//!   clamped to the disc `μ Σλ_i` (the points' summed normal impulses: Coulomb's law for the
//!   whole patch);
//! - **twisting** about the normal: the row `C' = n·(ω_b − ω_a) = 0`, Jacobian
//!   `[0, −n, 0, n]`, effective mass `K = n·I_a⁻¹ n + n·I_b⁻¹ n`, clamped to
//!   `|λ| ≤ μ Σλ_i d_i`, each point's normal impulse times its distance `d_i` from the centre
//!   in the contact plane (rapier's twist limit: the further a point, the more torque its
//!   friction can hold). A single point has `d = 0`, so a ball's contact has no twist, as per
//!   point.
//!
//! The twist is solved before the tangents (rapier's order: it changes the angular velocities
//! the tangent rows read at the centre's lever arm). Both are solved in the relax passes only,
//! as per-point friction is.
//!
//! What it gives up: per point, a box sliding on its corners feels each corner's friction at
//! that corner; per patch, all of it acts at the centre, and the twist's limit is the
//! uniform-pressure estimate of the corner friction's torque. Measured in
//! `scenarios/friction_models.rs` and `scenarios/convex.rs`: the same inclines, tipping, spun
//! box, 10-box stack and pyramid bounds as per point, but a 20-box stack sways 2.0 cm in 10 s
//! (0.6 cm per point), and a cylinder standing on a tessellated floor, whose four points are
//! not symmetric about its axis, begins to rock and slides 9.7 mm (0.5 mm per point): hence
//! per point is the default.

use super::anchor_drift::AnchorDrift;
use super::body::BodyParams;
use super::contact::RowPart;
use crate::geometry::MAX_MANIFOLD_POINTS;
use glam::Vec3;

/// How contacts resist sliding (see the [module](self) doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FrictionModel {
    /// Two friction rows at every point of a contact, each clamped to its own point's normal
    /// impulse (Box2D v3, Jolt, Avian).
    #[default]
    PerPoint,
    /// Two friction rows at the centre of a contact's points and a twist row about its normal
    /// (rapier's default, PhysX's patch friction): three rows a contact, whatever its points.
    Patch,
}

/// The friction rows of one contact under [`FrictionModel::Patch`], prepared once per step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PatchFriction {
    /// The two tangent rows at the patch centre.
    pub tangent_rows: [RowPart; 2],
    /// `I_a⁻¹ n`, `I_b⁻¹ n`: the twist's change of angular velocity per unit impulse.
    pub twist_turn: [Vec3; 2],
    /// `1/K` of the twist row (0 if neither body can turn).
    pub twist_mass: f32,
    /// Each point's distance from the centre in the contact plane (0 past the count).
    pub arms: [f32; MAX_MANIFOLD_POINTS],
    /// The tangent rows' drift targets at the centre (`anchor_drift.rs`).
    pub tangent_drift: [f32; 2],
    /// Accumulated impulses along the two tangents (N·s).
    pub tangent_impulse: [f32; 2],
    /// Accumulated twist impulse about the normal (N·m·s).
    pub twist_impulse: f32,
}

impl PatchFriction {
    /// The rows of a contact with `points` (world, at least one) and normal `n` between bodies
    /// of centres of mass `centers`; `sides` are the tangents with their translational parts
    /// `d·W_a d + d·W_b d` (as [`RowPart`] takes them); `drift` gives the tangent rows' targets
    /// (none: zero).
    pub(super) fn new(
        [pa, pb]: [&BodyParams; 2],
        points: &[Vec3],
        centers: [Vec3; 2],
        (n, sides): (Vec3, [(Vec3, f32); 2]),
        drift: Option<&AnchorDrift>,
    ) -> Self {
        let centre = points.iter().sum::<Vec3>() / points.len().max(1) as f32;
        let (ra, rb) = (centre - centers[0], centre - centers[1]);
        let twist_turn = [pa.inverse_inertia * n, pb.inverse_inertia * n];
        let k = n.dot(twist_turn[0] + twist_turn[1]);
        let mut arms = [0.0; MAX_MANIFOLD_POINTS];
        for (arm, p) in arms.iter_mut().zip(points) {
            let off = *p - centre;
            *arm = (off - n * off.dot(n)).length();
        }
        Self {
            tangent_rows: sides.map(|side| RowPart::new(pa, pb, ra, rb, side)),
            twist_turn,
            twist_mass: if k > 0.0 && k.is_finite() {
                1.0 / k
            } else {
                0.0
            },
            arms,
            tangent_drift: drift.map_or([0.0; 2], |d| d.at(ra, rb, d.relative(ra, rb))),
            tangent_impulse: [0.0; 2],
            twist_impulse: 0.0,
        }
    }

    /// The limits of the tangent disc and of the twist for the points' `normal_impulses`
    /// and the friction coefficient `mu`: `(μ Σλ_i, μ Σλ_i d_i)`.
    pub fn limits(&self, mu: f32, normal_impulses: impl Iterator<Item = f32>) -> (f32, f32) {
        let (mut sum, mut moment) = (0.0, 0.0);
        for (lambda, arm) in normal_impulses.zip(self.arms) {
            sum += lambda;
            moment += lambda * arm;
        }
        (mu * sum, mu * moment)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::solver::{
        BodyInput, ContactConstraint, ContactInput, ContactPointInput, RowSettings, Softness,
        SolverBodies, WarmStartCache,
    };
    use glam::Quat;

    /// A 1 kg cube (half-size 0.5) resting on a static ground, its four corners in contact.
    fn resting_box() -> (SolverBodies, ContactInput) {
        let mut bodies = SolverBodies::default();
        bodies.push(BodyInput::default());
        bodies.push(BodyInput {
            center: Vec3::new(0.0, 0.0, 0.5),
            orientation: Quat::from_rotation_z(0.3),
            inverse_mass: 1.0,
            inverse_principal_inertia: Vec3::splat(6.0),
            ..Default::default()
        });
        let mut points = [ContactPointInput::default(); MAX_MANIFOLD_POINTS];
        for (p, (x, y)) in points
            .iter_mut()
            .zip([(1., 1.), (-1., 1.), (-1., -1.), (1., -1.)])
        {
            p.point = Vec3::new(0.5 * x + 0.1, 0.5 * y, 0.0);
        }
        let input = ContactInput {
            a: 0,
            b: 1,
            normal: Vec3::Z,
            friction: 0.5,
            restitution: 0.0,
            rolling_resistance: 0.0,
            rounding: [0.0; 2],
            points,
            count: 4,
            key: 7,
        };
        (bodies, input)
    }

    fn prepare(bodies: &SolverBodies, input: &ContactInput, h: f32) -> ContactConstraint {
        let soft = Softness::new(60.0, 10.0, h);
        let (centers, states, params) = (&bodies.centers, &bodies.states, &bodies.params);
        let settings = RowSettings {
            softness: soft,
            friction: FrictionModel::Patch,
            step: 4.0 * h,
        };
        ContactConstraint::prepare(input, centers, states, params, settings)
    }

    #[test]
    fn a_square_patch_has_its_centre_at_the_mean_and_its_arms_at_the_corners_within_1e_6() {
        let (bodies, input) = resting_box();
        let c = prepare(&bodies, &input, 1.0 / 240.0);
        let patch = c.patch.expect("friction per patch");
        // No per-point friction rows.
        assert!(c.points().iter().all(|p| p.tangent_rows[0].mass == 0.0));
        for arm in patch.arms {
            assert!((arm - 0.5 * 2f32.sqrt()).abs() < 1e-6, "{arm}");
        }
        // The centre is 0.1 m off the box's axis: the tangent rows' lever arms see it.
        let rb = Vec3::new(0.1, 0.0, -0.5);
        for (row, t) in patch.tangent_rows.iter().zip(c.tangents) {
            assert!((row.arm[1] - rb.cross(t)).length() < 1e-6);
        }
        // Only B turns: K = n·I_b⁻¹ n = 6.
        assert!((patch.twist_mass - 1.0 / 6.0).abs() < 1e-6);
        let (disc, twist) = patch.limits(0.5, [1.0, 2.0, 3.0, 4.0].into_iter());
        assert!((disc - 5.0).abs() < 1e-6);
        assert!((twist - 5.0 * 0.5 * 2f32.sqrt()).abs() < 1e-5);
    }

    #[test]
    fn a_patchs_friction_and_twist_carry_to_the_next_step_scaled_by_the_substep_within_1e_6() {
        let (bodies, input) = resting_box();
        let mut c = prepare(&bodies, &input, 1.0 / 240.0);
        let patch = c.patch.as_mut().expect("friction per patch");
        patch.tangent_impulse = [0.3, -0.4];
        patch.twist_impulse = 0.02;
        let world = c.tangents[0] * 0.3 - c.tangents[1] * 0.4;
        let mut cache = WarmStartCache::default();
        let orientation = |a: u32| bodies.orientations[a as usize];
        cache.store(&[c], orientation, 1.0 / 240.0);
        // The next step at half the substep, with the same normal.
        let mut next = [prepare(&bodies, &input, 1.0 / 480.0)];
        cache.seed(&mut next, orientation, 1.0 / 480.0, 0.05);
        let seeded = next[0].patch.expect("friction per patch");
        let [f0, f1] = seeded.tangent_impulse;
        let carried = next[0].tangents[0] * f0 + next[0].tangents[1] * f1;
        assert!((carried - world * 0.5).length() < 1e-6, "{carried}");
        assert!((seeded.twist_impulse - 0.01).abs() < 1e-6);
        // Per point, the same cache seeds no patch.
        let per_point = FrictionModel::PerPoint;
        let soft = Softness::new(60.0, 10.0, 1.0 / 480.0);
        let (centers, states, params) = (&bodies.centers, &bodies.states, &bodies.params);
        let mut plain = [ContactConstraint::prepare(
            &input,
            centers,
            states,
            params,
            RowSettings {
                softness: soft,
                friction: per_point,
                step: 4.0 / 480.0,
            },
        )];
        cache.seed(&mut plain, orientation, 1.0 / 480.0, 0.05);
        assert!(plain[0].patch.is_none());
    }
}
