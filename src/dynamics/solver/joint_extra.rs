//! A joint's rows beyond its point rows: a weld's or a slider's angular lock, a hinge's
//! alignment rows, a slider's rows across its axis, and the rows on the joint's coordinate
//! (limits and motor on a hinge's angle, a slider's travel, a distance or a ball joint's
//! twist; a ball joint's swing cone). See [`super::joint`] for what each kind keeps.
//!
//! They live apart from the point rows (Box2D v3 keeps each joint kind's solver data in its
//! own struct): a free ball joint, the most common joint of nets, ropes and ragdoll-free
//! chains, has none, and its passes then stream a few hundred bytes instead of a kilobyte.

use super::body::BodyState;
use super::joint::{JointImpulses, PointRows};
use super::joint_input::{JointInput, JointKind, JointLimit, JointMotor};
use super::joint_rows::{AngularRows, AxisRow, PairMasses, hinge_directions};
use super::softness::Softness;
use glam::{Mat3, Quat, Vec3};

/// The rows of a joint beyond its point rows, and what they are taken from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct JointExtra {
    kind: JointKind,
    /// The joint frames in world at the step's start.
    frames: [Quat; 2],
    /// The angular lock's `K⁻¹ = (I_a⁻¹ + I_b⁻¹)⁻¹` (fixed and prismatic joints): its rows
    /// are the world axes, so it holds for the whole step.
    lock_inverse_mass: Mat3,
    /// The limits and motor on the joint's coordinate, as the passes apply them.
    limits: Limits,
    /// The rows where the bodies are now ([`Self::refresh`]).
    rows: ExtraRows,
}

/// The bounds and motor a joint's passes apply, taken from its kind once per step.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Limits {
    /// On the axis coordinate (a hinge's angle, a slider's travel, a distance, a twist).
    axis: Option<JointLimit>,
    /// On a ball joint's swing: at most the cone's angle.
    swing: Option<JointLimit>,
    /// On the axis coordinate.
    motor: Option<JointMotor>,
}

impl Limits {
    fn of(kind: JointKind) -> Self {
        let (mut axis, motor) = kind.limit_and_motor();
        // A distance is never below 0: a rope's lower bound of 0 would only stop a body
        // passing through the other's anchor.
        if let (JointKind::Distance { .. }, Some(l)) = (kind, axis.as_mut())
            && l.min <= 0.0
        {
            l.min = f32::NEG_INFINITY;
        }
        let swing = match kind {
            JointKind::Spherical {
                swing: Some(cone), ..
            } => Some(JointLimit {
                min: f32::NEG_INFINITY,
                max: cone,
            }),
            _ => None,
        };
        Self { axis, swing, motor }
    }
}

/// The extra rows where the bodies are now: they depend on the bodies' positions only, so
/// they are computed once per substep, after the positions move, and serve the relax passes,
/// the next substep's warm start and its biased pass (a limit row's pivot may wait for the
/// first pass that needs it: [`Pending`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct ExtraRows {
    angular: Option<(AngularRows, Vec3)>,
    across: Option<[(AxisRow, f32); 2]>,
    axis: Option<(AxisRow, f32)>,
    /// A ball joint's swing: the row turning B's axis away from A's, and the angle between.
    swing: Option<(AxisRow, f32)>,
    /// The angular rows' `K⁻¹`.
    angular_inverse_mass: Mat3,
    /// Which limit rows are to be held at the anchors but have no pivot yet
    /// ([`AxisRow::held_at`]): it is taken when a pass first needs the row's mass.
    pending: Pending,
}

/// The limit rows whose pivot waits for a pass that needs it. Taking a pivot costs a 3×3
/// product and two inertia products; most limit rows take no impulse in most passes (89 % of
/// the ragdoll pile's bound solves are skipped), and a row carrying an impulse into the substep
/// gets its pivot at once (the warm start applies it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Pending {
    axis: bool,
    swing: bool,
}

/// What one pass over a joint's rows needs besides the rows (borrowed apart from them, so the
/// rows are not copied).
pub(super) struct Pass<'a> {
    pub masses: &'a PairMasses,
    /// The joint's point rows where the bodies are now (a pending pivot is taken from them).
    pub point: &'a PointRows,
    pub ab: (usize, usize),
    pub soft: Softness,
    pub h: f32,
    pub use_bias: bool,
}

impl JointExtra {
    /// The extra rows of `joint` between bodies turned `qa`, `qb` at the step's start; none for
    /// a free ball joint (its point rows are all it has).
    pub(super) fn prepare(
        joint: &JointInput,
        masses: &PairMasses,
        (qa, qb): (Quat, Quat),
    ) -> Option<Self> {
        let free_ball = JointKind::Spherical {
            swing: None,
            twist: None,
        };
        if joint.kind == free_ball {
            return None;
        }
        let lock_inverse_mass =
            if matches!(joint.kind, JointKind::Fixed | JointKind::Prismatic { .. }) {
                AngularRows::world().inverse_mass(masses)
            } else {
                Mat3::ZERO
            };
        Some(Self {
            kind: joint.kind,
            frames: [qa * joint.frame_a.basis, qb * joint.frame_b.basis],
            lock_inverse_mass,
            limits: Limits::of(joint.kind),
            rows: ExtraRows::default(),
        })
    }

    /// The lock's inverse effective mass again, from `masses` as they are now (a body that
    /// turned within the step, `turned_rows.rs`).
    pub(super) fn take_masses(&mut self, masses: &PairMasses) {
        if matches!(self.kind, JointKind::Fixed | JointKind::Prismatic { .. }) {
            self.lock_inverse_mass = AngularRows::world().inverse_mass(masses);
        }
    }

    /// Takes the rows where bodies `sa`, `sb` are now, with the joint's `point` rows there;
    /// a limit row without an impulse `j` or a motor leaves its pivot pending.
    pub(super) fn refresh(
        &mut self,
        m: &PairMasses,
        (sa, sb): (&BodyState, &BodyState),
        point: &PointRows,
        j: &JointImpulses,
    ) {
        let ((r_a, r_b), separation) = (point.anchors, point.separation);
        let fa = sa.delta_rotation * self.frames[0];
        let fb = sb.delta_rotation * self.frames[1];
        let axis = fa * Vec3::X;
        let lock = || (AngularRows::world(), rotation_error(fa, fb));
        let mut rows = ExtraRows::default();
        let axis_carries =
            j.motor != 0.0 || j.lower != 0.0 || j.upper != 0.0 || self.limits.motor.is_some();
        match self.kind {
            JointKind::Fixed => {
                rows.angular = Some(lock());
                rows.angular_inverse_mass = self.lock_inverse_mass;
            }
            JointKind::Spherical { swing, twist } => {
                let axis_b = fb * Vec3::X;
                if swing.is_some()
                    && let Some((row, angle)) = swing_row(axis, axis_b)
                {
                    let (row, pending) = held_if(row, j.swing != 0.0, m, point);
                    (rows.swing, rows.pending.swing) = (Some((row, angle)), pending);
                }
                if twist.is_some() {
                    // Twist is about the axes' bisector, where both frames see it alike.
                    let bisector = (axis + axis_b).normalize_or(axis);
                    let row = AxisRow::angular(bisector);
                    let (row, pending) = held_if(row, axis_carries, m, point);
                    (rows.axis, rows.pending.axis) = (Some((row, twist_angle(fa, fb))), pending);
                }
            }
            JointKind::Revolute { .. } => {
                let (d, c) = hinge_directions(axis, [fb * Vec3::Y, fb * Vec3::Z]);
                let hinge = AngularRows {
                    directions: [d[0], d[1], Vec3::ZERO],
                    count: 2,
                };
                rows.angular = Some((hinge, Vec3::new(c[0], c[1], 0.0)));
                // The alignment rows turn with B: their effective mass is taken where they are.
                rows.angular_inverse_mass = hinge.inverse_mass(m);
                let (row, pending) = held_if(AxisRow::angular(axis), axis_carries, m, point);
                (rows.axis, rows.pending.axis) = (Some((row, twist_angle(fa, fb))), pending);
            }
            JointKind::Prismatic { .. } => {
                rows.angular = Some(lock());
                rows.angular_inverse_mass = self.lock_inverse_mass;
                let (rail, arms) = slider_rail(m, (fa, fb), (r_a, r_b), separation);
                let slide = |dir: Vec3| {
                    let row = AxisRow {
                        linear: dir,
                        angular_a: arms.0.cross(dir),
                        angular_b: arms.1.cross(dir),
                        pivot: None,
                    };
                    (row, dir.dot(separation))
                };
                rows.across = Some([slide(rail * Vec3::Y), slide(rail * Vec3::Z)]);
                rows.axis = Some(slide(rail * Vec3::X));
            }
            JointKind::Distance { .. } => {
                let length = separation.length();
                let n = if length > 1e-6 {
                    separation / length
                } else {
                    axis
                };
                rows.axis = Some((AxisRow::linear(n, r_a, r_b), length));
            }
        }
        self.rows = rows;
    }

    /// The linear impulse on B that the rows held at the anchors carry with impulses `j`
    /// ([`Pivot::point`](super::joint_rows::Pivot::point)), beyond the point rows' own.
    pub(super) fn pivoted_impulse(&self, j: &JointImpulses) -> Vec3 {
        let share = |row: &Option<(AxisRow, f32)>, impulse: f32| {
            row.as_ref()
                .and_then(|(row, _)| row.pivot)
                .map_or(Vec3::ZERO, |pivot| pivot.point * impulse)
        };
        share(&self.rows.axis, j.motor + j.lower - j.upper) + share(&self.rows.swing, -j.swing)
    }

    /// Applies the accumulated impulses of the extra rows.
    pub(super) fn apply_impulses(
        &self,
        m: &PairMasses,
        states: &mut [BodyState],
        ab: (usize, usize),
        j: &JointImpulses,
    ) {
        let rows = &self.rows;
        // `refresh` takes the pivot of a row that carries an impulse into the substep.
        debug_assert!(!rows.pending.axis || j.motor + j.lower - j.upper == 0.0);
        debug_assert!(!rows.pending.swing || j.swing == 0.0);
        if let Some((angular, _)) = rows.angular {
            let d = angular.directions;
            let world = d[0] * j.angular.x + d[1] * j.angular.y + d[2] * j.angular.z;
            m.apply(states, ab, Vec3::ZERO, [world, world]);
        }
        if let Some(across) = rows.across {
            for ((row, _), impulse) in across.iter().zip(j.across) {
                row.apply(m, states, ab, impulse);
            }
        }
        if let Some((row, _)) = rows.axis {
            row.apply(m, states, ab, j.motor + j.lower - j.upper);
        }
        if let Some((row, _)) = rows.swing {
            row.apply(m, states, ab, -j.swing);
        }
    }

    /// One pass over the extra rows: the motor and the limits, then the angular and across
    /// rows (the point rows, solved after these by the caller, come last: the hard rows win).
    pub(super) fn solve(&mut self, pass: &Pass, states: &mut [BodyState], j: &mut JointImpulses) {
        let rows = &mut self.rows;
        if rows.axis.is_some() || rows.swing.is_some() {
            pass.solve_coordinate(states, &self.limits, rows, j);
        }
        pass.solve_hard_rows(states, rows, j);
    }
}

impl Pass<'_> {
    /// The motor and the limits (a ball joint's swing cone among them).
    fn solve_coordinate(
        &self,
        states: &mut [BodyState],
        limits: &Limits,
        rows: &mut ExtraRows,
        j: &mut JointImpulses,
    ) {
        let (m, ab, h) = (self.masses, self.ab, self.h);
        if let Some((row, coordinate)) = &mut rows.axis {
            if let Some(motor) = &limits.motor {
                solve_motor(row, *coordinate, motor, m, states, ab, h, &mut j.motor);
            }
            if let Some(limit) = limits.axis {
                let row = (row, &mut rows.pending.axis);
                self.solve_limit(
                    row,
                    *coordinate,
                    limit,
                    states,
                    (&mut j.lower, &mut j.upper),
                );
            }
        }
        if let (Some((row, angle)), Some(limit)) = (&mut rows.swing, limits.swing) {
            let mut unused = 0.0;
            let row = (row, &mut rows.pending.swing);
            self.solve_limit(row, *angle, limit, states, (&mut unused, &mut j.swing));
        }
    }

    /// A limit's rows: an equal limit holds the coordinate; else each bound pushes only, and
    /// is speculative while not reached (it lets the coordinate close its gap this substep).
    /// The biased pass closes a violation softly; the relax passes are rigid. A bound that
    /// takes no impulse is skipped before its mass is needed; the row's pivot, if `pending`,
    /// is taken when one is.
    fn solve_limit(
        &self,
        (row, pending): (&mut AxisRow, &mut bool),
        coordinate: f32,
        limit: JointLimit,
        states: &mut [BodyState],
        (lower, upper): (&mut f32, &mut f32),
    ) {
        let (m, ab, h) = (self.masses, self.ab, self.h);
        let bias_of = |c: f32| match self.use_bias {
            true => (self.soft.bias_rate * c, self.soft),
            false => (0.0, Softness::RIGID),
        };
        if limit.min == limit.max {
            hold(row, pending, m, self.point);
            let (bias, soft) = bias_of(coordinate - limit.min);
            let free = (f32::NEG_INFINITY, f32::INFINITY);
            row.solve(m, states, ab, bias, soft, lower, free);
            return;
        }
        for (side, c, acc) in [
            (1.0, coordinate - limit.min, lower),
            (-1.0, limit.max - coordinate, upper),
        ] {
            if c == f32::INFINITY {
                // No bound there (a rope's, or one a game moved away): it carries nothing.
                *acc = 0.0;
                continue;
            }
            let (bias, soft) = if c > 0.0 {
                (c / h, Softness::RIGID)
            } else {
                bias_of(c)
            };
            // A bound that carries nothing and is not closing faster than its bias allows takes
            // nothing (89 % of the ragdoll pile's bound solves): skipped before its mass.
            let cdot = side * row.velocity(&states[ab.0], &states[ab.1]);
            if *acc == 0.0 && cdot + bias >= 0.0 {
                continue;
            }
            hold(row, pending, m, self.point);
            row.push_only(m, states, ab, (side, cdot), bias, soft, acc);
        }
    }

    /// The rows that hold the joint together besides the point rows: angular lock or
    /// alignment, the slider's rows across its axis.
    fn solve_hard_rows(&self, states: &mut [BodyState], rows: &ExtraRows, j: &mut JointImpulses) {
        let (m, ab, use_bias) = (self.masses, self.ab, self.use_bias);
        let bias_soft = if use_bias { self.soft } else { Softness::RIGID };
        if let Some((angular, c)) = &rows.angular {
            let k = &rows.angular_inverse_mass;
            let error = use_bias.then_some(*c);
            angular.solve(m, states, ab, error, bias_soft, k, &mut j.angular);
        }
        if let Some(across) = &rows.across {
            for ((row, c), acc) in across.iter().zip(&mut j.across) {
                let bias = if use_bias {
                    self.soft.bias_rate * c
                } else {
                    0.0
                };
                let free = (f32::NEG_INFINITY, f32::INFINITY);
                row.solve(m, states, ab, bias, bias_soft, acc, free);
            }
        }
    }
}

/// `row` held at the joint's anchors at once when it `carries` an impulse into the substep
/// (the warm start applies it) or drives a motor, else left for the first pass that needs it;
/// with whether it is left pending.
fn held_if(mut row: AxisRow, carries: bool, m: &PairMasses, point: &PointRows) -> (AxisRow, bool) {
    let mut pending = true;
    if carries {
        hold(&mut row, &mut pending, m, point);
    }
    (row, pending)
}

/// Holds `row` at the joint's anchors ([`AxisRow::held_at`]) if its pivot is `pending`.
fn hold(row: &mut AxisRow, pending: &mut bool, m: &PairMasses, point: &PointRows) {
    if std::mem::take(pending) {
        *row = row.held_at(m, point.anchors, &point.inverse_mass);
    }
}

/// The frame a slider's rail rides on, and the arms its rows turn the bodies by.
///
/// A slider keeps `C = d · s` at zero across its rail (and measures its travel along it), where
/// `s = c_b + r_b − c_a − r_a` runs anchor to anchor and `d` is one of the rail's directions.
/// If `d` turns with A, `Ċ = d · (v_b + ω_b × r_b − v_a − ω_a × r_a) + (ω_a × d) · s`, and
/// `(ω_a × d) · s = −ω_a · (s × d)`: A's arm is `r_a + s`, B's is `r_b`. If `d` turns with B,
/// the last term is `(ω_b × d) · s`: A's arm is `r_a`, B's `r_b − s`. Held rigidly the two are
/// the same joint (the angular rows keep the frames aligned), but a soft row gives where its
/// arm is long: a body sliding 6 m along a rail fixed in the world, with the rail on the body,
/// was held at the world's anchor 6 m from its centre, and the torque that took tilted it
/// until it sagged 195 mm under gravity. So the rail rides on the heavier body (on B when B is
/// strictly heavier, the world and static bodies included), whose arm the long one then is.
#[inline]
fn slider_rail(
    m: &PairMasses,
    (fa, fb): (Quat, Quat),
    (r_a, r_b): (Vec3, Vec3),
    separation: Vec3,
) -> (Quat, (Vec3, Vec3)) {
    let [wa, wb] = m.inverse_mass.map(Vec3::max_element);
    if wb < wa {
        (fb, (r_a, r_b - separation))
    } else {
        (fa, (r_a + separation, r_b))
    }
}

/// How far frame `fb` is turned from `fa`, as a world rotation vector (`2·vec(fb fa⁻¹)` on the
/// short way round: its rate is `ω_b − ω_a` for small errors).
fn rotation_error(fa: Quat, fb: Quat) -> Vec3 {
    let e = fb * fa.inverse();
    let e = if e.w < 0.0 { -e } else { e };
    2.0 * Vec3::new(e.x, e.y, e.z)
}

/// The angle `fb` is turned from `fa` about `fa`'s x axis, in `(−π, π]` (the twist of the
/// relative rotation; exact when the alignment rows hold the axes together).
pub fn twist_angle(fa: Quat, fb: Quat) -> f32 {
    let r = fa.inverse() * fb;
    let r = if r.w < 0.0 { -r } else { r };
    2.0 * r.x.atan2(r.w)
}

/// The row of a ball joint's swing: the angle between A's axis and B's, and the direction
/// turning B's away from A's (`n = a × b / |a × b|`: the angle's rate is `n · (ω_b − ω_a)`);
/// none when the axes are (anti)parallel and the direction is undefined.
fn swing_row(axis_a: Vec3, axis_b: Vec3) -> Option<(AxisRow, f32)> {
    let n = axis_a.cross(axis_b);
    let sin = n.length();
    (sin > 1e-6).then(|| (AxisRow::angular(n / sin), sin.atan2(axis_a.dot(axis_b))))
}

/// The motor's row: towards its speed (rigid), or towards its position as a spring; the
/// accumulated impulse within `max_force·h`.
#[allow(clippy::too_many_arguments)]
fn solve_motor(
    row: &AxisRow,
    coordinate: f32,
    motor: &JointMotor,
    m: &PairMasses,
    states: &mut [BodyState],
    ab: (usize, usize),
    h: f32,
    acc: &mut f32,
) {
    let (bias, soft) = match motor.target_position {
        Some(target) => {
            let soft = Softness::new(motor.hertz, motor.damping_ratio, h);
            // A spring of 0 Hz holds nothing (Softness would make it rigid).
            if motor.hertz <= 0.0 {
                (0.0, Softness::RIGID)
            } else {
                (soft.bias_rate * (coordinate - target), soft)
            }
        }
        None => (0.0, Softness::RIGID),
    };
    let max = motor.max_force.max(0.0) * h;
    let bias = bias - motor.target_velocity;
    row.solve(m, states, ab, bias, soft, acc, (-max, max));
}
