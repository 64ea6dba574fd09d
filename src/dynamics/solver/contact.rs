//! Contact constraints with lever arms: one row along the normal and two friction rows per
//! point, solved softly (Box2D v3's `contact_solver.c`, in 3D; the Jacobians as in Avian's
//! `contact/normal_part.rs` and Jolt's `AxisConstraintPart`).
//!
//! # The normal row
//! For a point with anchors `r_a`, `r_b` (from each centre of mass) and normal `n` (A to B),
//! the separation is `C = (x_b + r_b − x_a − r_a)·n` and its rate
//!
//! `Ċ = (v_b + ω_b × r_b − v_a − ω_a × r_a)·n = J V`,
//! `J = [−nᵀ, −(r_a × n)ᵀ, nᵀ, (r_b × n)ᵀ]`,
//!
//! using `(ω × r)·n = ω·(r × n)`. The effective mass is `1/K` with
//! `K = J M⁻¹ Jᵀ = 1/m_a + 1/m_b + (r_a × n)·I_a⁻¹(r_a × n) + (r_b × n)·I_b⁻¹(r_b × n)`,
//! and an impulse `λ` changes the velocities by `M⁻¹ Jᵀ λ`: `v_a −= λn/m_a`,
//! `ω_a −= I_a⁻¹ (r_a × λn)`, and the opposite for B. A body with locked translation axes has
//! the diagonal `W = diag(1/m per axis)` (0 along a locked one) in place of `1/m`:
//! `K = n·W_a n + n·W_b n + …` and `v_a −= W_a λn`.
//!
//! # Separation during substeps
//! Contacts are found once per step. Within it each body has moved by `dp` and turned by `dq`
//! since the start, so the separation is updated without new detection (Box2D v3):
//! `s = s₀ + (dp_b − dp_a + dq_b r_b − dq_a r_a − (r_b − r_a))·n`; `s₀ − (r_b − r_a)·n` is kept
//! as the point's base separation, with the `r` of a body that stays still taken as zero
//! (`on_moving`: from a ground's centre it would round the separation to the ground's size).
//!
//! # Speculative and soft
//! A point still apart (`s > 0`) may close exactly its gap this substep (bias `s/h`): contacts
//! found before they touch stop bodies at the surface without bouncing or tunnelling. A point
//! in penetration is pushed out softly ([`Softness`]) at no more than `max_push_out`. The relax
//! pass solves again without bias, removing the velocity the push-out added, and friction
//! (Coulomb, both tangent rows clamped together to the disc `μ λ_n`) is solved in the relax
//! pass only, as Box2D does: friction in the biased pass fights the push-out and lets stacks
//! creep. Under [`FrictionModel::Patch`] the points carry no friction rows: the contact's
//! [`PatchFriction`] (two rows at the points' centre and a twist) takes their place.
//!
//! A friction row solves `J V + drift = 0`, not `J V = 0`: with the anchors held for the step,
//! a point sticking on a body that spins about the normal (a turntable) would move along the
//! step's chord and drift outward; `drift` (`anchor_drift.rs`, zero without such a spin) is
//! the velocity that keeps it on its arc.

use super::anchor_drift::{AnchorDrift, contact_share};
use super::body::{BodyParams, BodyState, same_on_every_axis};
use super::contact_pair::Pair;
use super::patch_friction::{FrictionModel, PatchFriction};
use super::rolling::RollingRows;
pub use super::row::{PointRow, RowPart};
use super::softness::Softness;
use crate::geometry::{FeatureId, MAX_MANIFOLD_POINTS, length_or_zero};
use glam::Vec3;

/// One point of a contact as detection found it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactPointInput {
    /// World point (between the surfaces).
    pub point: Vec3,
    /// Distance between the surfaces along the normal: negative in penetration.
    pub separation: f32,
    /// The features that made it (the narrow phase's [`FeatureId`]; `NONE`: matched by place
    /// for its warm start).
    pub feature: FeatureId,
}

/// A contact between two bodies (slots into [`SolverBodies`](super::SolverBodies)), with up to
/// [`MAX_MANIFOLD_POINTS`] points sharing a normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactInput {
    /// First body's slot.
    pub a: u32,
    /// Second body's slot.
    pub b: u32,
    /// Unit normal from A to B.
    pub normal: Vec3,
    /// Coulomb friction coefficient of the pair.
    pub friction: f32,
    /// Coefficient of restitution of the pair.
    pub restitution: f32,
    /// Lever arm of the pair's rolling resistance (m; 0: none; see [`RollingRows`]).
    pub rolling_resistance: f32,
    /// How far each body's surface lies outside its core at the contact (a ball's or a
    /// capsule's radius, 0 for a shape with faces, edges or corners:
    /// [`Shape::rounding`](crate::geometry::Shape::rounding)). A rounded body's contact stays
    /// its core's point plus this radius as it rolls: its separation does not grow as it turns
    /// and friction follows the contact across the other body (`anchor_drift.rs`).
    pub rounding: [f32; 2],
    /// The points (the first `count`).
    pub points: [ContactPointInput; MAX_MANIFOLD_POINTS],
    /// How many points are used.
    pub count: u8,
    /// A key stable from step to step for the same pair of colliders (warm starting follows
    /// it); contacts must be given in increasing key order.
    pub key: u128,
}

/// A point of a prepared constraint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ConstraintPoint {
    /// Anchor from A's centre of mass (world axes at the step's start).
    pub anchor_a: Vec3,
    /// Anchor from B's centre of mass.
    pub anchor_b: Vec3,
    /// `s₀ − (r_b − r_a)·n`, a still side's `r` zero (see the module doc).
    pub base_separation: f32,
    /// The normal row (its lever arms from the anchors: [`Self::row`]).
    pub normal_row: PointRow,
    /// The two friction rows.
    pub tangent_rows: [PointRow; 2],
    /// What the friction rows add to their relative velocity, `J V + drift = 0`: the drift
    /// of the anchors as the bodies turn over the step (`anchor_drift.rs`; zero when neither
    /// turns).
    pub tangent_drift: [f32; 2],
    /// Accumulated normal impulse of the current substep (N·s).
    pub normal_impulse: f32,
    /// Accumulated friction impulses along the two tangents.
    pub tangent_impulse: [f32; 2],
    /// Largest normal impulse of the step, warm start included (restitution skips points that
    /// never pushed).
    pub max_normal_impulse: f32,
    /// Normal relative velocity when the contact began to push (at the step's start for a
    /// contact already pushing): the approach speed restitution reverses. Taken at the substep
    /// of impact, not the step's start, so a bounce does not lose the speed gravity added
    /// during the step before it (and a body struck by another in the step passes the blow
    /// on), from the velocities before the pass's impulses on the contact, and for all its
    /// points at once, so the points of a face landing flat all read the same speed (read
    /// after the points solved before them, or a substep after the first pushed, they bounced
    /// differently and spun the body: `contact_normals.rs`, "One moment per impact").
    pub relative_velocity: f32,
    /// The features that made the point: last step's impulses of the same features seed it
    /// (`warm_start.rs`).
    pub feature: FeatureId,
}

impl ConstraintPoint {
    /// `row` (along `dir`) with its lever arms `r_a × d`, `r_b × d`, taken from the anchors
    /// (the bits `RowPart::new` stored: a point keeps no arms, see [`PointRow`]).
    #[inline(always)]
    pub fn row(&self, row: &PointRow, dir: Vec3) -> RowPart {
        row.with_arms(self.anchor_a, self.anchor_b, dir)
    }
}

/// A prepared contact: its rows and accumulated impulses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactConstraint {
    /// First body's slot.
    pub a: u32,
    /// Second body's slot.
    pub b: u32,
    /// Unit normal from A to B.
    pub normal: Vec3,
    /// Orthonormal tangents spanning the friction plane.
    pub tangents: [Vec3; 2],
    /// Coulomb coefficient.
    pub friction: f32,
    /// Restitution coefficient.
    pub restitution: f32,
    /// Softness of the push-out (stiffer against immovable bodies).
    pub softness: Softness,
    /// The points: the first `count` are used; the others may hold a former constraint's
    /// values ([`Self::refill`]) and are never read.
    pub points: [ConstraintPoint; MAX_MANIFOLD_POINTS],
    /// How many are used.
    pub count: u8,
    /// The caller's pair key.
    pub key: u128,
    /// Solve the points backwards this substep (flipped every substep).
    pub flip: bool,
    /// `1/m` of A and B per world axis (0 along a locked one), copied so the passes touch
    /// only the velocities.
    pub inverse_mass: [Vec3; 2],
    /// Whether a body is locked along some translation axes, not all: its `1/m` differs
    /// between axes, which the batches' one-number-per-body lanes cannot carry (such contacts
    /// are solved one at a time, so a scene without locks pays nothing for them).
    pub translation_locked: bool,
    /// Whether A and B may be moved (kinematic and static bodies keep their velocities).
    pub dynamic: [bool; 2],
    /// Whether A and B are immovable and at rest (velocities and motion since the step's start
    /// all `+0.0`, no turn), as they stay for the whole step: a batch whose lanes all have such
    /// a body on one side reads none of its state ([`ContactBatches`](super::batch)).
    pub still: [bool; 2],
    /// The rolling-resistance rows (none unless the pair has a lever arm).
    pub rolling: RollingRows,
    /// The friction rows of the whole patch under [`FrictionModel::Patch`] (the points' own
    /// tangent rows are then zero and unused).
    pub patch: Option<PatchFriction>,
    /// How fast the external accelerations (gravity, forces) close the gap along the normal:
    /// `(a_b − a_a)·n` (m/s²), to carry a speculative point's approach speed on to the moment
    /// it touches.
    pub closing_acceleration: f32,
    /// Whether a point closes or parts faster than [`IMPACT_SPEED`] at the step's start: only
    /// then are the points swept more than once a pass (`contact_normals.rs`).
    pub impact: bool,
    /// Whether a body spins about the normal (`anchor_drift.rs`): only then may the friction
    /// rows have a drift target, and a batch without one solves its rows without it.
    pub turning: bool,
    /// A's and B's rounding ([`ContactInput::rounding`], finite and `>= 0`): a rounded
    /// side's separation follows its core as it turns (`contact_normals.rs`).
    pub rounding: [f32; 2],
}

/// How a step prepares its contacts' rows ([`ContactConstraint::prepare`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RowSettings {
    /// Softness of the push-out.
    pub softness: Softness,
    /// Friction rows per point or per patch.
    pub friction: FrictionModel,
    /// The step's duration (s), over which the anchors are held (the friction rows' drift,
    /// `anchor_drift.rs`).
    pub step: f32,
}

/// A point's anchor `r` as the separation reads it: zero on a still body
/// ([`ContactConstraint::still`]), `r` on the others.
///
/// Why: a still body neither moves nor turns in the step, and its velocities and inverse mass
/// are zero, so its anchor's only part in a pass is the separation, where `r·n` is taken off
/// the base separation and added back in every pass. From a ground's centre that number is as
/// large as the ground, and the small separation went through it: a ball resting on a 1 m
/// slab, 0.5 m above its centre, read its separation to twice its own float spacing, and the
/// solver's answer to that rounding moved it by one ulp every step, for ever (0.49998274 and
/// 0.49998277 m in turn). Taken from the point itself, the still side adds nothing. The rows
/// may read the zero too (their arm on a still body meets a zero angular velocity and a zero
/// inverse inertia); the warm start keeps the true anchors.
#[inline]
pub(super) fn on_moving(still: bool, r: Vec3) -> Vec3 {
    if still { Vec3::ZERO } else { r }
}

/// Whether a body's state is [`BodyState::default`], the rest state, bit for bit (`-0.0` is not
/// `+0.0` here): a batch reading the rest state's constants instead then computes the same bits.
fn at_rest(state: &BodyState) -> bool {
    let bits = |s: &BodyState| {
        let [v, w, p] = [s.linear_velocity, s.angular_velocity, s.delta_position]
            .map(|v| v.to_array().map(f32::to_bits));
        (v, w, p, s.delta_rotation.to_array().map(f32::to_bits))
    };
    bits(state) == bits(&BodyState::default())
}

/// The two friction directions square to `n` between bodies locked along an axis (`w`, the
/// pair's per-axis inverse mass, has a smallest entry): the second is that axis as far as it
/// is square to `n`, so the first lies in the plane the bodies move in (without locks, any
/// pair: `any_orthonormal_pair`, inline in the caller, the hot path).
///
/// Why: a 2D game's bodies (translation locked along z, turning about z only) each move in the
/// xy plane, and a contact normal there, `(ε, 1, 0)`, got glam's pair `(1, −ε, −ε)`,
/// `(−ε, 0, −1)`: the in-plane friction direction was split between two rows coupled through
/// the bodies' masses, and per point they never settled. Two boxes stacked on a floor kept
/// sliding at 3 cm/s and turning at 0.1 rad/s, and a pile of 40 never slept (a user-style
/// probe); with the same lock about y and gravity along −z the pair came out in the plane and
/// they rested.
#[cold]
fn friction_directions_locked(n: Vec3, w: Vec3) -> [Vec3; 2] {
    let axis = Vec3::AXES[w.min_position()];
    match (axis - n * n.dot(axis)).try_normalize() {
        Some(across) => [across.cross(n), across],
        None => {
            let (t1, t2) = n.any_orthonormal_pair();
            [t1, t2]
        }
    }
}

/// A contact's row directions with their translational parts `d·W d` (`W` the pair's per-axis
/// `1/m`: `1/m_a + 1/m_b` itself without locks, bit for bit what the solver computed before it
/// had per-axis masses), as [`RowPart::new`] takes them.
struct RowDirections {
    normal: (Vec3, f32),
    sides: [(Vec3, f32); 2],
}

impl RowDirections {
    #[inline(always)]
    fn new(n: Vec3, tangents: [Vec3; 2], w: Vec3) -> Self {
        let uniform = same_on_every_axis(w);
        let along = |d: Vec3| (d, if uniform { w.x } else { w.dot(d * d) });
        Self {
            normal: along(n),
            sides: tangents.map(along),
        }
    }

    /// A point's normal row at anchors `r` on bodies `p`.
    #[inline(always)]
    fn normal_row(&self, [pa, pb]: [&BodyParams; 2], [ra, rb]: [Vec3; 2]) -> PointRow {
        RowPart::new(pa, pb, ra, rb, self.normal).into()
    }

    /// A point's two tangent rows with friction per point (zero rows without).
    #[inline(always)]
    fn tangent_rows(
        &self,
        [pa, pb]: [&BodyParams; 2],
        [ra, rb]: [Vec3; 2],
        per_point: bool,
    ) -> [PointRow; 2] {
        // Written out, not `sides.map(..)`: the map's closure was not inlined and read its
        // side back through memory, stalled on the stores that wrote it.
        if per_point {
            [
                RowPart::new(pa, pb, ra, rb, self.sides[0]).into(),
                RowPart::new(pa, pb, ra, rb, self.sides[1]).into(),
            ]
        } else {
            [PointRow::default(); 2]
        }
    }
}

/// Restitution within `0..=1`; a non-finite value (which would fling both bodies to infinity)
/// is 0, and more than 1 (a bounce that gains energy) is 1.
fn sane_restitution(e: f32) -> f32 {
    if e.is_finite() {
        e.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The normal speed at which a point approaching at `vn` (< 0) from `s` away meets the surface:
/// a speculative point first pushes a substep before it touches, and the step's accelerations
/// (`closing`, < 0 when they close the gap) keep acting until it does: `v² = vn² − 2 a s`. A
/// bounce then starts from the speed of the real impact (dropped balls came back 2.6 % short at
/// 60 Hz without this). Touching or penetrating points keep `vn`.
pub(super) fn impact_speed(vn: f32, s: f32, closing: f32) -> f32 {
    if s <= 0.0 || vn >= 0.0 {
        return vn;
    }
    let squared = vn * vn - 2.0 * closing * s;
    if squared.is_finite() && squared > vn * vn {
        -squared.sqrt()
    } else {
        vn
    }
}

/// Velocity of the point at `r` of a body.
pub(super) fn point_velocity(s: &BodyState, r: Vec3) -> Vec3 {
    s.linear_velocity + s.angular_velocity.cross(r)
}

impl ContactConstraint {
    /// Builds the rows from detection data at the step's start (`centers`: centres of mass),
    /// with friction rows per point or per patch as `settings` say.
    pub fn prepare(
        input: &ContactInput,
        centers: &[Vec3],
        states: &[BodyState],
        params: &[BodyParams],
        settings: RowSettings,
    ) -> Self {
        let mut c = Self {
            a: 0,
            b: 0,
            normal: Vec3::ZERO,
            tangents: [Vec3::ZERO; 2],
            friction: 0.0,
            restitution: 0.0,
            softness: settings.softness,
            points: [ConstraintPoint::default(); MAX_MANIFOLD_POINTS],
            count: 0,
            key: 0,
            flip: false,
            inverse_mass: [Vec3::ZERO; 2],
            translation_locked: false,
            dynamic: [false; 2],
            still: [false; 2],
            rolling: RollingRows::default(),
            patch: None,
            closing_acceleration: 0.0,
            impact: false,
            turning: false,
            rounding: [0.0; 2],
        };
        c.refill(input, centers, states, params, settings);
        c
    }

    /// [`Self::prepare`] in place, over last step's constraint in the same place of the list:
    /// a constraint is about a kilobyte (four points of three rows), and building each one to
    /// move it into the list copied it twice and cleared its unused points, a tenth of a
    /// pile's preparation. The points past [`Self::points`] keep stale values; nothing reads
    /// them. Always inlined into the step's loop: the locked pairs' friction directions grew it
    /// past the compiler's threshold, and called out of line it cost the falling pile 0.9 % more
    /// instructions (`valgrind --tool=callgrind`, 300 steps: 7,852 against 7,779 million;
    /// inlined, 7,750).
    #[inline(always)]
    pub fn refill(
        &mut self,
        input: &ContactInput,
        centers: &[Vec3],
        states: &[BodyState],
        params: &[BodyParams],
        settings: RowSettings,
    ) {
        let RowSettings {
            softness,
            friction: model,
            step,
        } = settings;
        let (ia, ib) = (input.a as usize, input.b as usize);
        let (pa, pb) = (&params[ia], &params[ib]);
        let n = input.normal;
        // `d·W d` for unit `d`: `1/m_a + 1/m_b` itself without locks (bit for bit what the
        // solver computed before it had per-axis masses).
        let w = pa.inverse_mass + pb.inverse_mass;
        let uniform = same_on_every_axis(w);
        let tangents = if uniform {
            let (t1, t2) = n.any_orthonormal_pair();
            [t1, t2]
        } else {
            friction_directions_locked(n, w)
        };
        let directions = RowDirections::new(n, tangents, w);
        let count = (input.count as usize).min(MAX_MANIFOLD_POINTS);
        let per_point = model == FrictionModel::PerPoint;
        let still = [(pa, ia), (pb, ib)].map(|(p, i)| !p.dynamic && at_rest(&states[i]));
        let (sa, sb) = (&states[ia], &states[ib]);
        let rounding = input.rounding.map(length_or_zero);
        let drift = AnchorDrift::new([sa, sb], (n, tangents), rounding, step);
        for (cp, p) in self.points.iter_mut().zip(&input.points[..count]) {
            let ra = p.point - centers[ia];
            let rb = p.point - centers[ib];
            let gap_arms = [on_moving(still[0], ra), on_moving(still[1], rb)];
            let relative = point_velocity(sb, rb) - point_velocity(sa, ra);
            *cp = ConstraintPoint {
                anchor_a: ra,
                anchor_b: rb,
                base_separation: p.separation - (gap_arms[1] - gap_arms[0]).dot(n),
                normal_row: directions.normal_row([pa, pb], [ra, rb]),
                tangent_rows: directions.tangent_rows([pa, pb], [ra, rb], per_point),
                tangent_drift: match &drift {
                    Some(drift) if per_point => drift.at(ra, rb, relative),
                    _ => [0.0; 2],
                },
                relative_velocity: relative.dot(n),
                feature: p.feature,
                ..Default::default()
            };
        }
        self.a = input.a;
        self.b = input.b;
        self.normal = n;
        self.tangents = tangents;
        self.friction = input.friction.max(0.0);
        self.restitution = sane_restitution(input.restitution);
        self.softness = softness;
        self.count = count as u8;
        self.key = input.key;
        self.flip = false;
        self.inverse_mass = [pa.inverse_mass, pb.inverse_mass];
        self.translation_locked =
            !same_on_every_axis(pa.inverse_mass) || !same_on_every_axis(pb.inverse_mass);
        self.dynamic = [pa.dynamic, pb.dynamic];
        self.still = still;
        self.turning = drift.is_some();
        self.rounding = rounding;
        self.closing_acceleration = (pb.linear_acceleration - pa.linear_acceleration).dot(n);
        let fast = |p: &ConstraintPoint| p.relative_velocity.abs() > IMPACT_SPEED;
        self.impact = self.points[..count].iter().any(fast);
        self.rolling = RollingRows::new(
            input.rolling_resistance,
            tangents,
            [pa.inverse_inertia, pb.inverse_inertia],
        );
        self.patch = (!per_point && count > 0).then(|| {
            let points = input.points.map(|p| p.point);
            PatchFriction::new(
                [pa, pb],
                &points[..count],
                [centers[ia], centers[ib]],
                (n, directions.sides),
                drift.as_ref(),
            )
        });
    }

    /// The rows again with the bodies' inverse inertias as `params` hold them now (a body
    /// that turned within the step, `turned_rows.rs`): the anchors, directions and impulses
    /// stay. Friction per patch keeps the step's rows.
    pub fn refresh_rows(&mut self, params: &[BodyParams]) {
        let (pa, pb) = (&params[self.a as usize], &params[self.b as usize]);
        let w = self.inverse_mass[0] + self.inverse_mass[1];
        let directions = RowDirections::new(self.normal, self.tangents, w);
        let per_point = self.patch.is_none();
        for cp in &mut self.points[..self.count as usize] {
            let anchors = [cp.anchor_a, cp.anchor_b];
            cp.normal_row = directions.normal_row([pa, pb], anchors);
            if per_point {
                cp.tangent_rows = directions.tangent_rows([pa, pb], anchors, per_point);
            }
        }
        if self.rolling.arm > 0.0 {
            let impulse = self.rolling.impulse;
            let inertia = [pa.inverse_inertia, pb.inverse_inertia];
            self.rolling = RollingRows::new(self.rolling.arm, self.tangents, inertia);
            self.rolling.impulse = impulse;
        }
    }

    /// The used points.
    pub fn points(&self) -> &[ConstraintPoint] {
        &self.points[..self.count as usize]
    }

    /// Applies the accumulated impulses (warm start): the previous substep's answer is the best
    /// first guess for this one.
    pub fn warm_start(&self, states: &mut [BodyState]) {
        let mut pair = Pair::load(self, states);
        for cp in self.points() {
            pair.push(self, self.normal, &cp.normal_row.turn, cp.normal_impulse);
            if self.patch.is_none() {
                for k in 0..2 {
                    let turn = &cp.tangent_rows[k].turn;
                    pair.push(self, self.tangents[k], turn, cp.tangent_impulse[k]);
                }
            }
        }
        if let Some(patch) = &self.patch {
            for k in 0..2 {
                let (t, row) = (self.tangents[k], &patch.tangent_rows[k]);
                pair.push(self, t, &row.turn, patch.tangent_impulse[k]);
            }
            pair.twist(patch, patch.twist_impulse);
        }
        if self.rolling.arm > 0.0 {
            let Pair { wa, wb, .. } = &mut pair;
            self.rolling.warm_start(wa, wb);
        }
        pair.store(self, states);
    }

    /// One pass over the rows: non-penetration (biased when `use_bias`), then friction when
    /// relaxing, aiming at `drift_share` of its drift targets (`(2k + 1)/n` in substep `k` of
    /// `n`, `anchor_drift.rs`; a contact between two dynamic bodies takes 1).
    pub fn solve(
        &mut self,
        states: &mut [BodyState],
        (inv_h, max_push_out): (f32, f32),
        use_bias: bool,
        drift_share: f32,
    ) {
        let mut pair = Pair::load(self, states);
        self.solve_normals(&mut pair, states, (inv_h, max_push_out), use_bias);
        let count = self.count as usize;
        if !use_bias && self.friction > 0.0 {
            if let Some(patch) = &mut self.patch {
                let normal = self.points[..count].iter().map(|p| p.normal_impulse);
                let limits = patch.limits(self.friction, normal);
                let directions = (self.normal, self.tangents);
                let share = contact_share(self.dynamic, drift_share);
                pair.solve_patch(patch, limits, directions, (self.inverse_mass, share));
            } else {
                self.solve_point_friction(&mut pair, contact_share(self.dynamic, drift_share));
            }
        }
        if !use_bias && self.rolling.arm > 0.0 {
            let normal: f32 = self.points[..count].iter().map(|p| p.normal_impulse).sum();
            let Pair { wa, wb, .. } = &mut pair;
            self.rolling.solve(wa, wb, self.tangents, normal);
        }
        pair.store(self, states);
    }

    /// Coulomb friction at each point: both tangent rows clamped together to the disc
    /// `μ λ_n` of the point's own normal impulse, aiming at `share` of the drift targets.
    fn solve_point_friction(&mut self, pair: &mut Pair, share: f32) {
        for cp in &mut self.points[..self.count as usize] {
            let [old0, old1] = cp.tangent_impulse;
            if cp.normal_impulse == 0.0 && old0 == 0.0 && old1 == 0.0 {
                // No normal force, no friction held: the row would change nothing (a
                // speculative point still apart, as between a pyramid's side neighbours).
                continue;
            }
            let limit = self.friction * cp.normal_impulse;
            let rows = [0, 1].map(|k| cp.row(&cp.tangent_rows[k], self.tangents[k]));
            let [drift0, drift1] = cp.tangent_drift;
            cp.tangent_impulse = pair.solve_disc(
                &rows,
                self.tangents,
                (cp.tangent_impulse, [drift0 * share, drift1 * share]),
                (limit, self.inverse_mass),
            );
        }
    }
}

#[path = "contact_normals.rs"]
mod normals;
pub use normals::{IMPACT_SPEED, MAX_SWEEPS, SETTLED_SPEED};

#[cfg(test)]
#[path = "contact_tests.rs"]
mod tests;
