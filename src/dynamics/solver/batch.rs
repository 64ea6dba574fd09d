//! Four contacts solved at once: the rows of [`ContactConstraint`] laid out one contact per
//! SIMD lane (Box2D v3's `contact_solver.c` wide path, rapier's `ContactWithTwistFriction<SimdReal>`).
//!
//! The contacts of a batch move no common body
//! ([`OrderedBatches`](super::ordered_batches::OrderedBatches)), so no two lanes write the same
//! velocities: the batch gathers its bodies' velocities, runs exactly the
//! scalar solver's arithmetic ([`ContactConstraint::solve`], whose module derives the rows) in
//! every lane, and scatters the velocities back. A lane whose contact has fewer points than the
//! batch's largest, and the padding lanes of a short batch, hold zero rows: their impulses come
//! out zero and change nothing, so no lane needs a mask.
//!
//! The batch is packed from the prepared constraints once per step and its impulses unpacked
//! into them after the substeps, so restitution, warm-start storage and contact reports read
//! the constraints as before.

use super::body::BodyState;
use super::contact::{ConstraintPoint, ContactConstraint, RowPart};
use super::lanes::{LANES, Lanes, PairVelocities, Quatx4, Vec3x4, lanes_of};
use super::patch_friction::PatchFriction;
use crate::geometry::MAX_MANIFOLD_POINTS;
use glam::Vec3;

/// One row of four contacts' points ([`RowPart`] per lane).
#[derive(Clone, Copy, Debug, Default)]
struct RowX4 {
    arm: [Vec3x4; 2],
    turn: [Vec3x4; 2],
    mass: Lanes,
}

impl RowX4 {
    // Written out, not `[0, 1].map(..)`: the array map's drain stayed out of line.
    fn gather(rows: [&RowPart; LANES]) -> Self {
        let side = |part: fn(&RowPart) -> Vec3| Vec3x4::gather(rows.map(part));
        Self {
            arm: [side(|r| r.arm[0]), side(|r| r.arm[1])],
            turn: [side(|r| r.turn[0]), side(|r| r.turn[1])],
            mass: Lanes::new(rows.map(|r| r.mass)),
        }
    }
}

/// A point's row as a batch keeps it: [`RowX4`] without the lever arms `r × d`, which each pass
/// takes from the point's anchors ([`PointX4::row`]: the arithmetic of [`RowPart::new`], so the
/// same bits). A third less to read per point and pass: the passes stream every batch from
/// memory several times a substep, and once a scene's batches outgrow the processor's cache
/// that traffic, not the arithmetic, sets the pace (a 3D pyramid of 1,015 boxes: 1.13× rapier's
/// time at 204 boxes, 1.37× at 1,015, with 1.11× its instructions in both).
#[derive(Clone, Copy, Debug, Default)]
struct PointRowX4 {
    turn: [Vec3x4; 2],
    mass: Lanes,
}

impl PointRowX4 {
    fn gather(rows: [&RowPart; LANES]) -> Self {
        let side = |part: fn(&RowPart) -> Vec3| Vec3x4::gather(rows.map(part));
        Self {
            turn: [side(|r| r.turn[0]), side(|r| r.turn[1])],
            mass: Lanes::new(rows.map(|r| r.mass)),
        }
    }
}

/// The `k`-th point of four contacts ([`ConstraintPoint`] per lane).
#[derive(Clone, Copy, Debug, Default)]
struct PointX4 {
    anchor_a: Vec3x4,
    anchor_b: Vec3x4,
    base_separation: Lanes,
    normal_row: PointRowX4,
    tangent_rows: [PointRowX4; 2],
    normal_impulse: Lanes,
    tangent_impulse: [Lanes; 2],
    max_normal_impulse: Lanes,
    relative_velocity: Lanes,
}

impl PointX4 {
    fn gather(points: [&ConstraintPoint; LANES]) -> Self {
        let each = |f: fn(&ConstraintPoint) -> f32| Lanes::new(points.map(f));
        Self {
            anchor_a: Vec3x4::gather(points.map(|p| p.anchor_a)),
            anchor_b: Vec3x4::gather(points.map(|p| p.anchor_b)),
            base_separation: each(|p| p.base_separation),
            normal_row: PointRowX4::gather(points.map(|p| &p.normal_row)),
            tangent_rows: [
                PointRowX4::gather(points.map(|p| &p.tangent_rows[0])),
                PointRowX4::gather(points.map(|p| &p.tangent_rows[1])),
            ],
            normal_impulse: each(|p| p.normal_impulse),
            tangent_impulse: [
                each(|p| p.tangent_impulse[0]),
                each(|p| p.tangent_impulse[1]),
            ],
            max_normal_impulse: each(|p| p.max_normal_impulse),
            relative_velocity: each(|p| p.relative_velocity),
        }
    }

    /// `row` (along `dir`) with its lever arms `r_a × d`, `r_b × d`.
    #[inline(always)]
    fn row(&self, row: &PointRowX4, dir: Vec3x4) -> RowX4 {
        RowX4 {
            arm: [self.anchor_a.cross(dir), self.anchor_b.cross(dir)],
            turn: row.turn,
            mass: row.mass,
        }
    }

    /// Writes lane `lane`'s impulses and approach speed into `point`.
    fn scatter(&self, lane: usize, point: &mut ConstraintPoint) {
        let at = |v: &Lanes| v.as_array()[lane];
        point.normal_impulse = at(&self.normal_impulse);
        point.tangent_impulse = self.tangent_impulse.each_ref().map(at);
        point.max_normal_impulse = at(&self.max_normal_impulse);
        point.relative_velocity = at(&self.relative_velocity);
    }
}

/// Four contacts' [`PatchFriction`] (zero rows in lanes without one).
#[derive(Clone, Copy, Debug, Default)]
struct PatchX4 {
    tangent_rows: [RowX4; 2],
    twist_turn: [Vec3x4; 2],
    twist_mass: Lanes,
    arms: [Lanes; MAX_MANIFOLD_POINTS],
    tangent_impulse: [Lanes; 2],
    twist_impulse: Lanes,
}

impl PatchX4 {
    fn gather(patches: [&PatchFriction; LANES]) -> Self {
        let each = |f: fn(&PatchFriction) -> f32| Lanes::new(patches.map(f));
        let side = |f: fn(&PatchFriction) -> Vec3| Vec3x4::gather(patches.map(f));
        Self {
            tangent_rows: [
                RowX4::gather(patches.map(|p| &p.tangent_rows[0])),
                RowX4::gather(patches.map(|p| &p.tangent_rows[1])),
            ],
            twist_turn: [side(|p| p.twist_turn[0]), side(|p| p.twist_turn[1])],
            twist_mass: each(|p| p.twist_mass),
            arms: std::array::from_fn(|k| Lanes::new(patches.map(|p| p.arms[k]))),
            tangent_impulse: [
                each(|p| p.tangent_impulse[0]),
                each(|p| p.tangent_impulse[1]),
            ],
            twist_impulse: each(|p| p.twist_impulse),
        }
    }

    /// Writes lane `lane`'s impulses into `patch`.
    fn scatter(&self, lane: usize, patch: &mut PatchFriction) {
        let at = |v: &Lanes| v.as_array()[lane];
        patch.tangent_impulse = self.tangent_impulse.each_ref().map(at);
        patch.twist_impulse = at(&self.twist_impulse);
    }
}

/// Up to four contacts that move no common body, solved side by side.
#[derive(Clone, Debug, Default)]
pub struct ContactBatch {
    /// Which constraint each lane holds (`None`: padding).
    constraints: [Option<u32>; LANES],
    /// Body slots of A and B per lane (padding lanes repeat lane 0's).
    bodies: [[usize; LANES]; 2],
    /// Whether the lane writes A's and B's velocities back (dynamic bodies of real lanes).
    writes: [[bool; LANES]; 2],
    normal: Vec3x4,
    tangents: [Vec3x4; 2],
    friction: Lanes,
    inverse_mass: [Lanes; 2],
    /// `mass_scale · bias_rate`, `mass_scale`, `impulse_scale` of each lane's softness.
    softness: [Lanes; 3],
    closing_acceleration: Lanes,
    points: [PointX4; MAX_MANIFOLD_POINTS],
    /// The most points any lane has.
    count: usize,
    /// Whether any lane has friction.
    rubs: bool,
    /// The lanes' friction per patch (zero where a lane has none).
    patch: PatchX4,
    /// Whether the lanes carry friction per patch, not per point (the solver's one
    /// [`FrictionModel`](super::FrictionModel) for every contact).
    patched: bool,
}

impl ContactBatch {
    /// Packs `indices` (1 to [`LANES`] constraints moving no common body) of `constraints`;
    /// `None` for no index, more than [`LANES`] or an index out of range.
    pub fn pack(indices: &[u32], constraints: &[ContactConstraint]) -> Option<Self> {
        let mut batch = Self::default();
        batch.repack(indices, constraints).then_some(batch)
    }

    /// [`Self::pack`] into this batch, in place (the solver refills last step's batches: a
    /// batch is a few kilobytes, and building one to move it into the list copied it twice);
    /// false, the batch left as it was, where `pack` gives `None`. Only the points some lane
    /// has are gathered: the passes never read past the batch's point count.
    pub fn repack(&mut self, indices: &[u32], constraints: &[ContactConstraint]) -> bool {
        let Some((lanes, first)) = lanes_of(indices, constraints) else {
            return false;
        };
        let real = |l: usize| lanes[l].unwrap_or(first);
        let each = |f: fn(&ContactConstraint) -> f32| {
            Lanes::new(std::array::from_fn(|l| lanes[l].map_or(0.0, f)))
        };
        let vectors = |f: fn(&ContactConstraint) -> Vec3| {
            Vec3x4::gather(std::array::from_fn(|l| lanes[l].map_or(Vec3::ZERO, f)))
        };
        self.constraints = std::array::from_fn(|l| indices.get(l).copied());
        self.bodies = [
            std::array::from_fn(|l| real(l).a as usize),
            std::array::from_fn(|l| real(l).b as usize),
        ];
        self.writes =
            [0, 1].map(|k| std::array::from_fn(|l| lanes[l].is_some_and(|c| c.dynamic[k])));
        self.normal = vectors(|c| c.normal);
        self.tangents = [vectors(|c| c.tangents[0]), vectors(|c| c.tangents[1])];
        self.friction = each(|c| c.friction);
        debug_assert!(
            lanes.iter().flatten().all(|c| !c.translation_locked),
            "contacts of a body locked along some translation axes are solved one at a time"
        );
        self.inverse_mass = [each(|c| c.inverse_mass[0].x), each(|c| c.inverse_mass[1].x)];
        self.softness = [
            each(|c| c.softness.mass_scale * c.softness.bias_rate),
            each(|c| c.softness.mass_scale),
            each(|c| c.softness.impulse_scale),
        ];
        self.closing_acceleration = each(|c| c.closing_acceleration);
        self.count = lanes
            .iter()
            .flatten()
            .map(|c| c.count as usize)
            .max()
            .unwrap_or(0);
        debug_assert!(
            self.count <= MAX_MANIFOLD_POINTS,
            "prepare caps a contact's points"
        );
        let zero = ConstraintPoint::default();
        for (k, point) in self.points[..self.count].iter_mut().enumerate() {
            *point = PointX4::gather(std::array::from_fn(|l| match lanes[l] {
                Some(c) if k < c.count as usize => &c.points[k],
                _ => &zero,
            }));
        }
        self.rubs = lanes.iter().flatten().any(|c| c.friction > 0.0);
        self.patched = lanes.iter().flatten().any(|c| c.patch.is_some());
        if self.patched {
            let none = PatchFriction::default();
            self.patch =
                PatchX4::gather(lanes.map(|c| c.and_then(|c| c.patch.as_ref()).unwrap_or(&none)));
        }
        true
    }

    /// Writes the impulses and approach speeds back into the constraints the lanes came from.
    pub fn unpack(&self, constraints: &mut [ContactConstraint]) {
        for (lane, index) in self.constraints.iter().enumerate() {
            let Some(index) = index else { continue };
            let c = &mut constraints[*index as usize];
            for (point, wide) in c.points[..c.count as usize].iter_mut().zip(&self.points) {
                wide.scatter(lane, point);
            }
            if let Some(patch) = &mut c.patch {
                self.patch.scatter(lane, patch);
            }
        }
    }

    /// Applies the accumulated impulses ([`ContactConstraint::warm_start`] per lane).
    pub fn warm_start(&self, states: &mut [BodyState]) {
        let mut pair = PairVelocities::load(&self.bodies, states);
        if self.patched {
            self.warm_start_patch(&mut pair);
        } else {
            for p in &self.points[..self.count] {
                let row = p.row(&p.normal_row, self.normal);
                pair.push(self.inverse_mass, self.normal, &row, p.normal_impulse);
                for k in 0..2 {
                    let t = self.tangents[k];
                    let row = p.row(&p.tangent_rows[k], t);
                    pair.push(self.inverse_mass, t, &row, p.tangent_impulse[k]);
                }
            }
        }
        pair.store(&self.bodies, &self.writes, states);
    }

    /// The warm start of the normal rows and of a patch's friction (out of line, as
    /// [`Self::solve_patch`]).
    #[inline(never)]
    fn warm_start_patch(&self, pair: &mut PairVelocities) {
        for p in &self.points[..self.count] {
            let row = p.row(&p.normal_row, self.normal);
            pair.push(self.inverse_mass, self.normal, &row, p.normal_impulse);
        }
        let patch = &self.patch;
        for k in 0..2 {
            let (t, row) = (self.tangents[k], &patch.tangent_rows[k]);
            pair.push(self.inverse_mass, t, row, patch.tangent_impulse[k]);
        }
        pair.twist(patch, patch.twist_impulse);
    }

    /// One pass over the rows ([`ContactConstraint::solve`] per lane; `flip` visits the points
    /// backwards).
    pub fn solve(
        &mut self,
        states: &mut [BodyState],
        inv_h: f32,
        max_push_out: f32,
        use_bias: bool,
        flip: bool,
    ) {
        let mut pair = PairVelocities::load(&self.bodies, states);
        self.solve_normals(&mut pair, states, inv_h, max_push_out, use_bias, flip);
        if !use_bias && self.rubs {
            if self.patched {
                self.solve_patch(&mut pair);
            } else {
                self.solve_friction(&mut pair);
            }
        }
        pair.store(&self.bodies, &self.writes, states);
    }

    /// The normal rows: speculative points close their gap, penetrating ones are pushed out
    /// softly when `use_bias`.
    fn solve_normals(
        &mut self,
        pair: &mut PairVelocities,
        states: &[BodyState],
        inv_h: f32,
        max_push_out: f32,
        use_bias: bool,
        flip: bool,
    ) {
        let [slots_a, slots_b] = self.bodies;
        let moved = Vec3x4::gather(slots_b.map(|i| states[i].delta_position))
            - Vec3x4::gather(slots_a.map(|i| states[i].delta_position));
        let dqa = Quatx4::gather(slots_a.map(|i| states[i].delta_rotation));
        let dqb = Quatx4::gather(slots_b.map(|i| states[i].delta_rotation));
        let (zero, one) = (Lanes::ZERO, Lanes::ONE);
        let [bias_rate, soft_mass, soft_impulse] = if use_bias {
            self.softness
        } else {
            [zero, one, zero]
        };
        let (inv_h, most_push) = (Lanes::splat(inv_h), Lanes::splat(-max_push_out));
        let n = self.normal;
        // The normal in each body's rotation since the step's start, once for all points (see
        // `ContactConstraint::solve`).
        let (moved, na, nb) = (moved.dot(n), dqa.inverse_rotate(n), dqb.inverse_rotate(n));
        for k in 0..self.count {
            let i = if flip { self.count - 1 - k } else { k };
            let p = &mut self.points[i];
            let s = p.base_separation + moved + p.anchor_b.dot(nb) - p.anchor_a.dot(na);
            let apart = s.simd_gt(zero);
            let push_out = if use_bias {
                (bias_rate * s).max(most_push)
            } else {
                zero
            };
            let bias = apart.select(s * inv_h, push_out);
            let mass_scale = apart.select(one, soft_mass);
            let impulse_scale = apart.select(zero, soft_impulse);
            let row = &p.row(&p.normal_row, n);
            let vn = pair.along(n, row);
            let impulse = -row.mass * (mass_scale * vn + bias) - impulse_scale * p.normal_impulse;
            let total = (p.normal_impulse + impulse).max(zero);
            pair.push(self.inverse_mass, n, row, total - p.normal_impulse);
            let first = p.max_normal_impulse.simd_eq(zero) & total.simd_gt(zero);
            if first.any() {
                let speed = impact_speed(vn, s, self.closing_acceleration);
                p.relative_velocity = first.select(speed, p.relative_velocity);
            }
            p.normal_impulse = total;
            p.max_normal_impulse = p.max_normal_impulse.max(total);
        }
    }

    /// Coulomb friction at each point: both tangent rows clamped together to the disc `μ λ_n`.
    fn solve_friction(&mut self, pair: &mut PairVelocities) {
        let zero = Lanes::ZERO;
        for p in &mut self.points[..self.count] {
            let [old0, old1] = p.tangent_impulse;
            let idle = p.normal_impulse.simd_eq(zero) & old0.simd_eq(zero) & old1.simd_eq(zero);
            if idle.all() {
                continue;
            }
            let limit = self.friction * p.normal_impulse;
            let rows = [0, 1].map(|k| p.row(&p.tangent_rows[k], self.tangents[k]));
            p.tangent_impulse = pair.solve_disc(
                &rows,
                self.tangents,
                p.tangent_impulse,
                (limit, self.inverse_mass),
            );
        }
    }

    /// Friction per patch ([`PatchFriction`]): the twist, then the tangent disc at the centre,
    /// within `μ Σλ_i d_i` and `μ Σλ_i`. Kept out of line: inlined, it changed how the
    /// per-point passes were compiled (+4 % instructions on a pyramid).
    #[inline(never)]
    fn solve_patch(&mut self, pair: &mut PairVelocities) {
        let zero = Lanes::ZERO;
        let patch = &mut self.patch;
        let (mut sum, mut moment) = (zero, zero);
        for (p, arm) in self.points[..self.count].iter().zip(patch.arms) {
            sum += p.normal_impulse;
            moment += p.normal_impulse * arm;
        }
        let (limit, twist_limit) = (self.friction * sum, self.friction * moment);
        let old = patch.twist_impulse;
        let [old0, old1] = patch.tangent_impulse;
        let idle =
            limit.simd_eq(zero) & old.simd_eq(zero) & old0.simd_eq(zero) & old1.simd_eq(zero);
        if idle.all() {
            return;
        }
        let wanted = old - patch.twist_mass * self.normal.dot(pair.wb - pair.wa);
        let twist = wanted.max(-twist_limit).min(twist_limit);
        pair.twist(patch, twist - old);
        patch.twist_impulse = twist;
        let rows = &patch.tangent_rows;
        patch.tangent_impulse = pair.solve_disc(
            rows,
            self.tangents,
            patch.tangent_impulse,
            (limit, self.inverse_mass),
        );
    }
}

/// [`contact`](super::contact)'s `impact_speed` per lane: a speculative point approaching at
/// `vn` from `s` away meets the surface at `−√(vn² − 2 a s)`.
fn impact_speed(vn: Lanes, s: Lanes, closing: Lanes) -> Lanes {
    let zero = Lanes::ZERO;
    let squared = vn * vn - Lanes::splat(2.0) * closing * s;
    let faster =
        s.simd_gt(zero) & vn.simd_lt(zero) & squared.is_finite() & squared.simd_gt(vn * vn);
    faster.select(-squared.sqrt(), vn)
}

/// What a contact row reads of its bodies' velocities and adds to them.
impl PairVelocities {
    /// The rate of a row: `d·(v_b − v_a) + (r_b × d)·ω_b − (r_a × d)·ω_a`.
    fn along(&self, dir: Vec3x4, row: &RowX4) -> Lanes {
        dir.dot(self.vb - self.va) + row.arm[1].dot(self.wb) - row.arm[0].dot(self.wa)
    }

    /// An impulse `λ d` on B at its anchor, `−λ d` on A.
    fn push(&mut self, inverse_mass: [Lanes; 2], dir: Vec3x4, row: &RowX4, lambda: Lanes) {
        self.va = self.va - dir * (lambda * inverse_mass[0]);
        self.wa = self.wa - row.turn[0] * lambda;
        self.vb = self.vb + dir * (lambda * inverse_mass[1]);
        self.wb = self.wb + row.turn[1] * lambda;
    }

    /// An angular impulse `λ n` on B, `−λ n` on A (a patch's twist row).
    fn twist(&mut self, patch: &PatchX4, lambda: Lanes) {
        self.wa = self.wa - patch.twist_turn[0] * lambda;
        self.wb = self.wb + patch.twist_turn[1] * lambda;
    }

    /// Two tangent rows clamped together to the disc `|λ| ≤ limit`, as the scalar rows: the new
    /// accumulated impulses from the `old` ones.
    #[inline(always)]
    fn solve_disc(
        &mut self,
        [r0, r1]: &[RowX4; 2],
        [t0, t1]: [Vec3x4; 2],
        [old0, old1]: [Lanes; 2],
        (limit, inverse_mass): (Lanes, [Lanes; 2]),
    ) -> [Lanes; 2] {
        let (zero, one) = (Lanes::ZERO, Lanes::ONE);
        let w0 = old0 - r0.mass * self.along(t0, r0);
        let w1 = old1 - r1.mass * self.along(t1, r1);
        let length = (w0 * w0 + w1 * w1).sqrt();
        let clamped = length.simd_gt(limit) & length.simd_gt(zero);
        let scale = clamped.select(limit / length, one);
        let (new0, new1) = (w0 * scale, w1 * scale);
        self.push(inverse_mass, t0, r0, new0 - old0);
        self.push(inverse_mass, t1, r1, new1 - old1);
        [new0, new1]
    }
}

#[cfg(test)]
#[path = "batch_tests.rs"]
mod tests;
