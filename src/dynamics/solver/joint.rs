//! Joints in the solver: fixed, spherical (ball), revolute (hinge), prismatic (slider) and
//! distance (rope, rod, spring) joints between two solver bodies, with limits and motors, solved
//! in the same soft-step substeps as the contacts (Box2D v3's `joint.c` and
//! `revolute_joint.c`: warm started, soft while biased, rigid while relaxing; Avian's and
//! rapier's joints offer the same kinds).
//!
//! A joint holds each body at a frame (an anchor and a basis in the body's frame, the anchor
//! measured from the centre of mass). The joint's *axis* is its frames' x axis: the hinge's
//! axis, the slider's direction. What each kind keeps, from the rows of [`joint_rows`]:
//!
//! | kind | point rows | angular rows | axis coordinate (limit, motor) |
//! | --- | --- | --- | --- |
//! | fixed | 3 (anchors together) | 3 (frames aligned) | — |
//! | spherical | 3 | — (a swing cone and a twist limit if asked) | — |
//! | revolute | 3 | 2 (axes aligned) | angle of B's frame about A's axis |
//! | prismatic | 2 (across the axis) | 3 | travel of B's anchor along A's axis |
//! | distance | — | — | distance between the anchors |
//!
//! Per substep a joint is warm started with its accumulated impulses, then solved in each pass:
//! motor, limits, then the rows that hold it together (Box2D's order: the hard rows last, so
//! they win). The position errors are measured from the bodies' motion within the step
//! (`dp`, `dq`, as the contacts do), so the anchors turn with their bodies. In the biased pass
//! the errors are closed softly ([`SoftStepSettings::joint_hertz`](super::SoftStepSettings));
//! the relax passes are rigid and unbiased; a limit not yet reached is speculative, as a
//! contact is: it lets the coordinate close exactly its gap this substep. A motor is a soft
//! row of its own: a velocity motor is rigid towards its speed, a position motor is a spring
//! of the motor's stiffness, and both are bounded by the motor's force per substep.
//!
//! [`joint_rows`]: super::joint_rows

use super::body::{BodyState, SolverBodies};
use super::joint_rows::{
    AngularRows, AxisRow, PairMasses, hinge_directions, inverse_mass, point_mass, solve_point,
};
use super::softness::Softness;
use glam::{Mat3, Quat, Vec3};

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

impl JointImpulses {
    /// Every impulse times `factor`.
    fn scale(&mut self, factor: f32) {
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
}

/// A joint prepared for a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointConstraint {
    /// The caller's joint.
    pub input: JointInput,
    masses: PairMasses,
    /// Anchors from the centres of mass, world, at the step's start.
    anchors: [Vec3; 2],
    /// `c_b − c_a` at the step's start.
    delta_center: Vec3,
    /// The joint frames in world at the step's start.
    frames: [Quat; 2],
    /// The angular lock's `K⁻¹ = (I_a⁻¹ + I_b⁻¹)⁻¹` (fixed and prismatic joints): its rows
    /// are the world axes, so it holds for the whole step.
    lock_inverse_mass: Mat3,
    /// The limits and motor on the joint's coordinate, as the passes apply them.
    limits: Limits,
    /// Accumulated impulses.
    pub impulses: JointImpulses,
    /// The rows where the bodies are now ([`Self::refresh`]).
    rows: Rows,
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

/// The joint's rows where the bodies are now: they depend on the bodies' positions only, so
/// they are computed once per substep, after the positions move, and serve the relax passes,
/// the next substep's warm start and its biased pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Rows {
    anchors: (Vec3, Vec3),
    /// Anchor to anchor, `c_b + r_b − c_a − r_a`.
    separation: Vec3,
    angular: Option<(AngularRows, Vec3)>,
    across: Option<[(AxisRow, f32); 2]>,
    axis: Option<(AxisRow, f32)>,
    /// A ball joint's swing: the row turning B's axis away from A's, and the angle between.
    swing: Option<(AxisRow, f32)>,
    /// The point rows' `K⁻¹` (taken where the anchors are, as Box2D does: a step-start one
    /// overshot on a fast-swinging chain and diverged).
    point_inverse_mass: Mat3,
    /// The angular rows' `K⁻¹`.
    angular_inverse_mass: Mat3,
}

impl JointConstraint {
    /// Prepares `joint` over `bodies` at the step's start.
    pub fn prepare(joint: &JointInput, bodies: &SolverBodies) -> Self {
        let (a, b) = (joint.a as usize, joint.b as usize);
        let (qa, qb) = (bodies.orientations[a], bodies.orientations[b]);
        let mut c = Self {
            input: *joint,
            masses: PairMasses::of(&bodies.params, a, b),
            anchors: [qa * joint.frame_a.anchor, qb * joint.frame_b.anchor],
            delta_center: bodies.centers[b] - bodies.centers[a],
            frames: [qa * joint.frame_a.basis, qb * joint.frame_b.basis],
            lock_inverse_mass: Mat3::ZERO,
            limits: Limits::of(joint.kind),
            impulses: JointImpulses::default(),
            rows: Rows::default(),
        };
        if matches!(joint.kind, JointKind::Fixed | JointKind::Prismatic { .. }) {
            c.lock_inverse_mass = AngularRows::world().inverse_mass(&c.masses);
        }
        // The bodies have not moved yet.
        let start = BodyState::default();
        c.rows = c.rows_of(&start, &start);
        c
    }

    /// Takes the rows where the bodies are now (after their positions moved).
    pub fn refresh(&mut self, states: &[BodyState]) {
        let (a, b) = self.slots();
        self.rows = self.rows_of(&states[a], &states[b]);
    }

    fn slots(&self) -> (usize, usize) {
        (self.input.a as usize, self.input.b as usize)
    }

    /// The rows, from A's and B's motion since the step's start (frames only for the kinds
    /// that turn or limit).
    fn rows_of(&self, sa: &BodyState, sb: &BodyState) -> Rows {
        let r_a = sa.delta_rotation * self.anchors[0];
        let r_b = sb.delta_rotation * self.anchors[1];
        let separation = self.delta_center + sb.delta_position - sa.delta_position + r_b - r_a;
        let mut rows = Rows {
            anchors: (r_a, r_b),
            separation,
            ..Default::default()
        };
        if self.holds_point() {
            rows.point_inverse_mass = inverse_mass(point_mass(&self.masses, r_a, r_b));
        }
        let free_ball = JointKind::Spherical {
            swing: None,
            twist: None,
        };
        if self.input.kind == free_ball {
            return rows;
        }
        let fa = sa.delta_rotation * self.frames[0];
        let fb = sb.delta_rotation * self.frames[1];
        let axis = fa * Vec3::X;
        let lock = || (AngularRows::world(), rotation_error(fa, fb));
        match self.input.kind {
            JointKind::Fixed => {
                rows.angular = Some(lock());
                rows.angular_inverse_mass = self.lock_inverse_mass;
            }
            JointKind::Spherical { swing, twist } => {
                let axis_b = fb * Vec3::X;
                let m = &self.masses;
                if swing.is_some() {
                    let held = |(row, a): (AxisRow, f32)| (row.held_at(m, r_a, r_b), a);
                    rows.swing = swing_row(axis, axis_b).map(held);
                }
                if twist.is_some() {
                    // Twist is about the axes' bisector, where both frames see it alike.
                    let bisector = (axis + axis_b).normalize_or(axis);
                    let row = AxisRow::angular(bisector).held_at(m, r_a, r_b);
                    rows.axis = Some((row, twist_angle(fa, fb)));
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
                rows.angular_inverse_mass = hinge.inverse_mass(&self.masses);
                let row = AxisRow::angular(axis).held_at(&self.masses, r_a, r_b);
                rows.axis = Some((row, twist_angle(fa, fb)));
            }
            JointKind::Prismatic { .. } => {
                rows.angular = Some(lock());
                rows.angular_inverse_mass = self.lock_inverse_mass;
                let slide = |dir: Vec3| {
                    let row = AxisRow {
                        linear: dir,
                        angular_a: (r_a + separation).cross(dir),
                        angular_b: r_b.cross(dir),
                        pivot: None,
                    };
                    (row, dir.dot(separation))
                };
                rows.across = Some([slide(fa * Vec3::Y), slide(fa * Vec3::Z)]);
                rows.axis = Some(slide(axis));
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
        rows
    }

    /// Applies the accumulated impulses.
    pub fn warm_start(&self, states: &mut [BodyState]) {
        self.apply_impulses(states, self.slots());
    }

    /// Scales the impulses carried from the last step down so that applying them changes
    /// neither body's velocity by more than `max_speed` nor its spin by more than `max_spin`,
    /// and drops them if they are not finite. A joint fighting another one that holds the same
    /// body somewhere else (two joints to static bodies at places the body cannot reach at
    /// once) otherwise grows its rigid passes' impulses step after step until they overflow.
    /// The bound is per joint: a sound joint can reach it too where a light, thin body carries
    /// a heavy one (a 0.2 kg rod holding 10 kg 10 cm off its axis), and is then held to it.
    /// Returns whether it changed the impulses.
    pub fn bound_impulses(&mut self, max_speed: f32, max_spin: f32) -> bool {
        if self.impulses == JointImpulses::default() {
            return false;
        }
        let mut effect = [BodyState::default(); 2];
        self.apply_impulses(&mut effect, (0, 1));
        let finite = effect
            .iter()
            .all(|s| s.linear_velocity.is_finite() && s.angular_velocity.is_finite());
        if !finite {
            self.impulses = JointImpulses::default();
            return true;
        }
        let over = effect
            .iter()
            .map(|s| {
                let speed = s.linear_velocity.length_squared() / (max_speed * max_speed);
                let spin = s.angular_velocity.length_squared() / (max_spin * max_spin);
                speed.max(spin)
            })
            .fold(0.0f32, f32::max);
        if over > 1.0 {
            self.impulses.scale(1.0 / over.sqrt());
        }
        over > 1.0
    }

    /// Applies the accumulated impulses to the bodies in `states` at slots `ab`.
    fn apply_impulses(&self, states: &mut [BodyState], ab: (usize, usize)) {
        let rows = &self.rows;
        let m = &self.masses;
        let j = &self.impulses;
        if self.holds_point() {
            let (r_a, r_b) = rows.anchors;
            m.apply(
                states,
                ab,
                j.point,
                [r_a.cross(j.point), r_b.cross(j.point)],
            );
        }
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

    /// One pass: biased (`soft` closes the position errors) or relaxing (rigid, no bias).
    pub fn solve(&mut self, states: &mut [BodyState], soft: Softness, h: f32, use_bias: bool) {
        let holds_point = self.holds_point();
        let pass = Pass {
            masses: &self.masses,
            ab: self.slots(),
            soft,
            h,
            use_bias,
        };
        let (rows, impulses) = (&self.rows, &mut self.impulses);
        if rows.axis.is_some() || rows.swing.is_some() {
            pass.solve_coordinate(states, &self.limits, rows, impulses);
        }
        // The hard rows last, so that they win.
        pass.solve_hard_rows(states, rows, impulses, holds_point);
    }

    fn holds_point(&self) -> bool {
        matches!(
            self.input.kind,
            JointKind::Fixed | JointKind::Spherical { .. } | JointKind::Revolute { .. }
        )
    }

    /// What the joint applied over the last substep of the step: its accumulated impulses
    /// over the substep `h`.
    pub fn load(&self, h: f32) -> HeldLoad {
        let j = &self.impulses;
        let axial = j.motor + j.lower - j.upper;
        let mut force = j.point.length() + Vec3::new(j.across[0], j.across[1], 0.0).length();
        let mut torque = j.angular.length() + j.swing.abs();
        match self.input.kind {
            JointKind::Revolute { .. } | JointKind::Spherical { .. } => torque += axial.abs(),
            _ => force += axial.abs(),
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

/// What one pass over a joint's rows needs besides the rows (borrowed apart from them, so the
/// rows are not copied).
struct Pass<'a> {
    masses: &'a PairMasses,
    ab: (usize, usize),
    soft: Softness,
    h: f32,
    use_bias: bool,
}

impl Pass<'_> {
    /// The motor and the limits (a ball joint's swing cone among them).
    fn solve_coordinate(
        &self,
        states: &mut [BodyState],
        limits: &Limits,
        rows: &Rows,
        j: &mut JointImpulses,
    ) {
        let (m, ab, h) = (self.masses, self.ab, self.h);
        let soft = (h, self.use_bias.then_some(self.soft));
        if let Some((row, coordinate)) = &rows.axis {
            if let Some(motor) = &limits.motor {
                solve_motor(row, *coordinate, motor, m, states, ab, h, &mut j.motor);
            }
            if let Some(limit) = limits.axis {
                let accumulated = (&mut j.lower, &mut j.upper);
                solve_limit(row, *coordinate, limit, m, states, ab, soft, accumulated);
            }
        }
        if let (Some((row, angle)), Some(limit)) = (&rows.swing, limits.swing) {
            let mut unused = 0.0;
            let accumulated = (&mut unused, &mut j.swing);
            solve_limit(row, *angle, limit, m, states, ab, soft, accumulated);
        }
    }

    /// The rows that hold the joint together: angular lock or alignment, the slider's rows
    /// across its axis, the point rows.
    fn solve_hard_rows(
        &self,
        states: &mut [BodyState],
        rows: &Rows,
        j: &mut JointImpulses,
        holds_point: bool,
    ) {
        let (m, ab, use_bias) = (self.masses, self.ab, self.use_bias);
        let bias_soft = if use_bias { self.soft } else { Softness::RIGID };
        let error = |c: Vec3| use_bias.then_some(c);
        if let Some((angular, c)) = &rows.angular {
            let k = &rows.angular_inverse_mass;
            angular.solve(m, states, ab, error(*c), bias_soft, k, &mut j.angular);
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
        if holds_point {
            let c = error(rows.separation);
            let k = &rows.point_inverse_mass;
            solve_point(m, states, ab, rows.anchors, c, bias_soft, k, &mut j.point);
        }
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

/// A limit's rows: an equal limit holds the coordinate; else each bound pushes only, and is
/// speculative while not reached (it lets the coordinate close its gap this substep). `soft`
/// closes a violation in the biased pass; the relax passes (`None`) are rigid.
#[allow(clippy::too_many_arguments)]
fn solve_limit(
    row: &AxisRow,
    coordinate: f32,
    limit: JointLimit,
    m: &PairMasses,
    states: &mut [BodyState],
    ab: (usize, usize),
    (h, soft): (f32, Option<Softness>),
    (lower, upper): (&mut f32, &mut f32),
) {
    let bias_of = |c: f32| match soft {
        Some(soft) => (soft.bias_rate * c, soft),
        None => (0.0, Softness::RIGID),
    };
    if limit.min == limit.max {
        let (bias, soft) = bias_of(coordinate - limit.min);
        let free = (f32::NEG_INFINITY, f32::INFINITY);
        row.solve(m, states, ab, bias, soft, lower, free);
        return;
    }
    let reversed = row.reversed();
    let push = (0.0, f32::INFINITY);
    for (row, c, acc) in [
        (row, coordinate - limit.min, lower),
        (&reversed, limit.max - coordinate, upper),
    ] {
        if c == f32::INFINITY {
            continue;
        }
        let (bias, soft) = if c > 0.0 {
            (c / h, Softness::RIGID)
        } else {
            bias_of(c)
        };
        row.solve(m, states, ab, bias, soft, acc, push);
    }
}
