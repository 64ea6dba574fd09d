//! Joints in the solver: fixed, spherical (ball), revolute (hinge), prismatic (slider) and
//! distance (rope, rod, spring) joints between two solver bodies, with limits and motors, solved
//! in the same soft-step substeps as the contacts (Box2D v3's `joint.c` and
//! `revolute_joint.c`: warm started, soft while biased, rigid while relaxing; Avian's and
//! rapier's joints offer the same kinds).
//!
//! A joint holds each body at a frame (an anchor and a basis in the body's frame, the anchor
//! measured from the centre of mass). The joint's *axis* is its frames' x axis: the hinge's
//! axis, the slider's direction. What each kind keeps, from the rows of [`joint_rows`] and
//! [`point_rows`]:
//!
//! | kind | point rows | angular rows | axis coordinate (limit, motor) |
//! | --- | --- | --- | --- |
//! | fixed | 3 (anchors together) | 3 (frames aligned) | — |
//! | spherical | 3 | — (a swing cone and a twist limit if asked) | — |
//! | revolute | 3 | 2 (axes aligned) | angle of B's frame about A's axis |
//! | prismatic | 2 (across the axis) | 3 | travel of B's anchor from A's along the axis |
//! | distance | — | — | distance between the anchors |
//!
//! Per substep a joint is warm started with its accumulated impulses, then solved in each pass:
//! motor, limits, then the rows that hold it together (Box2D's order: the hard rows last, so
//! they win). The position errors are measured from the bodies' motion within the step
//! (`dp`, `dq`, as the contacts do), so the anchors turn with their bodies. A slider's rail
//! rides on the heavier of its bodies (why: `slider_rail` in `joint_extra.rs`). In the biased pass
//! the errors are closed softly ([`SoftStepSettings::joint_hertz`](super::SoftStepSettings));
//! the relax passes are rigid and unbiased; a limit not yet reached is speculative, as a
//! contact is: it lets the coordinate close exactly its gap this substep. A motor is a soft
//! row of its own: a velocity motor is rigid towards its speed, a position motor is a spring
//! of the motor's stiffness, and both are bounded by the motor's force per substep.
//!
//! Each joint is stored in two parts, as Box2D v3 keeps its joints' solver data apart from
//! their definitions: [`JointConstraint`], what every pass reads (the two slots, their masses,
//! the point rows and the impulses, about 300 bytes), and its extra rows (`joint_extra.rs`)
//! only for the kinds that have them. On Box2D's `joint_grid` (10,000 balls, 19,800 ball
//! joints) the whole joint was a kilobyte, and streaming it five times a substep was most of
//! the step. Free ball joints are solved four at a time in SIMD lanes (`joint_batch.rs`).
//!
//! [`joint_rows`]: super::joint_rows
//! [`point_rows`]: super::point_rows

use super::body::{BodyState, SolverBodies};
use super::joint_rows::PairMasses;
use super::point_rows::{inverse_mass, point_mass, solve_point};
use super::softness::Softness;
use glam::{Mat3, Vec3};

pub use super::joint_extra::twist_angle;
pub use super::joint_input::{JointFrame, JointInput, JointKind, JointLimit, JointMotor};

/// The impulses a joint accumulated (per substep; carried to the next step's warm start).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointImpulses {
    /// On B at the anchors (world).
    pub point: Vec3,
    /// Per angular row (world axes for a lock, the two alignment rows of a hinge in x and y).
    pub angular: Vec3,
    /// A slider's two rows across its axis.
    pub across: [f32; 2],
    /// The motor's.
    pub motor: f32,
    /// The lower limit's (or an equal limit's).
    pub lower: f32,
    /// The upper limit's.
    pub upper: f32,
    /// A ball joint's swing cone's.
    pub swing: f32,
}

/// Whether a joint of `kind` holds its anchors together with point rows.
fn holds_point(kind: &JointKind) -> bool {
    matches!(
        kind,
        JointKind::Fixed | JointKind::Spherical { .. } | JointKind::Revolute { .. }
    )
}

impl JointImpulses {
    /// Every impulse times `factor`.
    pub(super) fn scale(&mut self, factor: f32) {
        self.point *= factor;
        self.angular *= factor;
        self.across = self.across.map(|a| a * factor);
        for x in [
            &mut self.motor,
            &mut self.lower,
            &mut self.upper,
            &mut self.swing,
        ] {
            *x *= factor;
        }
    }

    /// Drops the impulses of rows `kind` does not have (a motor switched off, a limit removed,
    /// the kind changed since the impulses were kept): the warm start must not apply them, a
    /// row that is not there has no pivot to apply them at, and a joint's reported load must
    /// not carry them. (A bound moved to infinity drops its own when a pass meets it.)
    pub(super) fn keep_rows_of(&mut self, kind: &JointKind) {
        if !holds_point(kind) {
            self.point = Vec3::ZERO;
        }
        let angular = matches!(
            kind,
            JointKind::Fixed | JointKind::Revolute { .. } | JointKind::Prismatic { .. }
        );
        if !angular {
            self.angular = Vec3::ZERO;
        }
        if !matches!(kind, JointKind::Prismatic { .. }) {
            self.across = [0.0; 2];
        }
        let (limit, motor) = kind.limit_and_motor();
        if motor.is_none() {
            self.motor = 0.0;
        }
        if limit.is_none() {
            (self.lower, self.upper) = (0.0, 0.0);
        }
        if !matches!(kind, JointKind::Spherical { swing: Some(_), .. }) {
            self.swing = 0.0;
        }
    }
}

/// What every pass over a joint reads: its bodies, their masses, its point rows and its
/// impulses (the other rows are in its `JointExtra`, `joint_extra.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointConstraint {
    /// The caller's key (the ECS passes the joint entity's bits).
    pub key: u64,
    /// Accumulated impulses.
    pub impulses: JointImpulses,
    /// The bodies' slots.
    slots: (u32, u32),
    /// The joint's extra rows in its list, if it has any.
    pub(super) extra: Option<u32>,
    /// Whether the point rows hold the anchors together (fixed, ball and hinge joints).
    holds_point: bool,
    /// Whether the joint's coordinate is an angle (hinge and ball joints): its motor and
    /// limits then apply torques.
    turns: bool,
    /// The bodies' masses.
    pub(super) masses: PairMasses,
    /// Anchors from the centres of mass, world, at the step's start.
    pub(super) anchors: [Vec3; 2],
    /// `c_b − c_a` at the step's start.
    pub(super) delta_center: Vec3,
    /// The point rows where the bodies are now ([`Self::refresh`]); a joint solved in lanes
    /// keeps its `K⁻¹` in its batch, not here.
    pub(super) point: PointRows,
}

/// A joint's anchors where the bodies are now, and the point rows' effective mass there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PointRows {
    /// `r_a`, `r_b`: the anchors from the centres of mass (world).
    pub anchors: (Vec3, Vec3),
    /// Anchor to anchor, `c_b + r_b − c_a − r_a`.
    pub separation: Vec3,
    /// The point rows' `K⁻¹` (taken where the anchors are, as Box2D does: a step-start one
    /// overshot on a fast-swinging chain and diverged), for joints solved one at a time; zero
    /// until taken: for joints without point rows, for joints in lanes (their batches take
    /// theirs), and for a free ball joint that moves no dynamic body (whose `K` is zero).
    pub inverse_mass: Mat3,
}

impl Default for PointRows {
    /// No anchors, and a zero `K⁻¹` (glam's default matrix is the identity, which would push).
    fn default() -> Self {
        Self {
            anchors: (Vec3::ZERO, Vec3::ZERO),
            separation: Vec3::ZERO,
            inverse_mass: Mat3::ZERO,
        }
    }
}

/// The arms `r_a`, `r_b` and the separation of a joint whose step-start anchors (from the
/// centres of mass, world) are `anchors` and centres `delta_center` apart, where bodies `sa`,
/// `sb` are now.
#[inline]
fn placed(
    anchors: [Vec3; 2],
    delta_center: Vec3,
    sa: &BodyState,
    sb: &BodyState,
) -> ((Vec3, Vec3), Vec3) {
    let r_a = sa.delta_rotation * anchors[0];
    let r_b = sb.delta_rotation * anchors[1];
    let separation = delta_center + sb.delta_position - sa.delta_position + r_b - r_a;
    ((r_a, r_b), separation)
}

impl JointConstraint {
    /// The part of `joint` every pass reads, over `bodies` at the step's start (the caller
    /// checked its slots; its extra rows are the list's).
    pub(super) fn prepare(joint: &JointInput, bodies: &SolverBodies) -> Self {
        let mut c = Self {
            key: joint.key,
            impulses: JointImpulses::default(),
            slots: (joint.a, joint.b),
            extra: None,
            holds_point: false,
            turns: false,
            masses: PairMasses::default(),
            anchors: [Vec3::ZERO; 2],
            delta_center: Vec3::ZERO,
            point: PointRows::default(),
        };
        c.refill(joint, bodies);
        c
    }

    /// [`Self::prepare`] in place, over last step's joint in the same place of the list: a
    /// joint is about 300 bytes, and building each one to move it into the list copied it
    /// (on a 10,000-body joint grid the copies were a twentieth of the step's wall time).
    pub(super) fn refill(&mut self, joint: &JointInput, bodies: &SolverBodies) {
        let (a, b) = (joint.a as usize, joint.b as usize);
        let (qa, qb) = (bodies.orientations[a], bodies.orientations[b]);
        self.key = joint.key;
        self.impulses = JointImpulses::default();
        self.slots = (joint.a, joint.b);
        self.extra = None;
        self.holds_point = holds_point(&joint.kind);
        self.turns = matches!(
            joint.kind,
            JointKind::Revolute { .. } | JointKind::Spherical { .. }
        );
        self.masses.fill(&bodies.params, a, b);
        let anchors = [qa * joint.frame_a.anchor, qb * joint.frame_b.anchor];
        let delta_center = bodies.centers[b] - bodies.centers[a];
        self.anchors = anchors;
        self.delta_center = delta_center;
        // The bodies have not moved yet. The point rows' `K⁻¹` waits for the packing: a
        // joint in lanes takes it there, four at a time (`take_point_mass` for the others).
        // The rows are placed from the values just computed, not read back from `self`: a
        // 16-byte load of a `Vec3` just stored in two pieces waits for both stores to land,
        // and did, a sixth of a joint net's refills.
        let start = BodyState::default();
        self.point = PointRows::default();
        (self.point.anchors, self.point.separation) = placed(anchors, delta_center, &start, &start);
    }

    /// Whether the joint is nothing but its point rows (a ball joint without limits): the
    /// joints that ride in [`JointBatch`](super::joint_batch::JointBatch)es.
    pub(super) fn is_free_ball(&self) -> bool {
        self.holds_point && self.extra.is_none()
    }

    /// The bodies' slots.
    pub(super) fn slots(&self) -> (usize, usize) {
        (self.slots.0 as usize, self.slots.1 as usize)
    }

    /// Takes the point rows where bodies `sa`, `sb` are now (after their positions moved),
    /// from their motion since the step's start.
    pub(super) fn refresh(&mut self, sa: &BodyState, sb: &BodyState) {
        self.move_rows(sa, sb);
        self.take_point_mass();
    }

    /// The anchors and the separation where bodies `sa`, `sb` are now.
    fn move_rows(&mut self, sa: &BodyState, sb: &BodyState) {
        (self.point.anchors, self.point.separation) =
            placed(self.anchors, self.delta_center, sa, sb);
    }

    /// The point rows' `K⁻¹` at the anchors as they are.
    pub(super) fn take_point_mass(&mut self) {
        if self.holds_point {
            let (r_a, r_b) = self.point.anchors;
            self.point.inverse_mass = inverse_mass(point_mass(&self.masses, r_a, r_b));
        }
    }

    /// Applies the point rows' accumulated impulse to the bodies in `states` at slots `ab`.
    pub(super) fn apply_point_impulse(&self, states: &mut [BodyState], ab: (usize, usize)) {
        if self.holds_point {
            let (r_a, r_b) = self.point.anchors;
            let p = self.impulses.point;
            self.masses
                .apply(states, ab, p, [r_a.cross(p), r_b.cross(p)]);
        }
    }

    /// One pass over the point rows: biased (`soft` closes the gap) or relaxing (rigid).
    pub(super) fn solve_point(&mut self, states: &mut [BodyState], soft: Softness, use_bias: bool) {
        if !self.holds_point {
            return;
        }
        let (point, ab) = (&self.point, self.slots());
        let bias_soft = if use_bias { soft } else { Softness::RIGID };
        let error = use_bias.then_some(point.separation);
        let k = &point.inverse_mass;
        let acc = &mut self.impulses.point;
        solve_point(
            &self.masses,
            states,
            ab,
            point.anchors,
            error,
            bias_soft,
            k,
            acc,
        );
    }

    /// What the joint applied over the last substep of the step: its accumulated impulses
    /// over the substep `h`, the point rows' with `pivoted`, the linear impulse its limit,
    /// motor or swing rows carried at the anchors ([`super::joint_rows::Pivot::point`]).
    pub(super) fn load(&self, h: f32, pivoted: Vec3) -> HeldLoad {
        let j = &self.impulses;
        let axial = j.motor + j.lower - j.upper;
        let point = j.point + pivoted;
        let mut force = point.length() + Vec3::new(j.across[0], j.across[1], 0.0).length();
        let mut torque = j.angular.length() + j.swing.abs();
        if self.turns {
            torque += axial.abs();
        } else {
            force += axial.abs();
        }
        HeldLoad {
            force: force / h,
            torque: torque / h,
            motor: j.motor / h,
        }
    }
}

/// What a joint applied over a substep, as forces (the impulses over the substep).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HeldLoad {
    /// Force (N): the point rows, a slider's rows across its axis, and a slider's or a
    /// distance joint's motor and limits.
    pub force: f32,
    /// Torque (N·m): the angular rows, a ball joint's swing cone, and a hinge's or a ball
    /// joint's motor and limits.
    pub torque: f32,
    /// The motor's share, signed along the joint's coordinate (N·m for a hinge, N for a slider
    /// or a distance joint; 0 without a motor): what a game reads as the effort its motor makes.
    pub motor: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_kept_impulse_of_a_row_the_joint_no_longer_has_is_dropped_and_the_others_kept() {
        let carried = JointImpulses {
            motor: 1.0,
            lower: 2.0,
            upper: 3.0,
            swing: 4.0,
            ..Default::default()
        };
        let rows = |kind: JointKind| {
            let mut j = carried;
            j.keep_rows_of(&kind);
            (j.motor, j.lower, j.upper, j.swing)
        };
        // A hinge whose motor and limit were switched off since the impulses were kept.
        let free = JointKind::Revolute {
            limit: None,
            motor: None,
        };
        assert_eq!(rows(free), (0.0, 0.0, 0.0, 0.0));
        let limit = Some(JointLimit {
            min: -1.0,
            max: 1.0,
        });
        let limited = JointKind::Revolute { limit, motor: None };
        assert_eq!(rows(limited), (0.0, 2.0, 3.0, 0.0));
        let cone = JointKind::Spherical {
            swing: Some(0.5),
            twist: limit,
        };
        assert_eq!(rows(cone), (0.0, 2.0, 3.0, 4.0));
        let motor = Some(JointMotor {
            target_velocity: 1.0,
            target_position: None,
            hertz: 0.0,
            damping_ratio: 0.0,
            max_force: 10.0,
        });
        let driven = JointKind::Prismatic { limit: None, motor };
        assert_eq!(rows(driven), (1.0, 0.0, 0.0, 0.0));
        // A distance always has its limit; a rope's missing bound drops its own in the pass.
        let rope = JointKind::Distance {
            limit: JointLimit { min: 0.0, max: 2.0 },
            motor: None,
        };
        assert_eq!(rows(rope), (0.0, 2.0, 3.0, 0.0));
        // Rows of another kind: a hinge turned into a distance keeps no point or angular impulse.
        let mut j = JointImpulses {
            point: Vec3::ONE,
            angular: Vec3::ONE,
            across: [1.0; 2],
            ..carried
        };
        j.keep_rows_of(&rope);
        assert_eq!(
            (j.point, j.angular, j.across),
            (Vec3::ZERO, Vec3::ZERO, [0.0; 2])
        );
    }
}
