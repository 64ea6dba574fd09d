//! Four contacts solved at once: the rows of [`ContactConstraint`] laid out one contact per
//! SIMD lane (Box2D v3's `contact_solver.c` wide path, rapier's `ContactWithTwistFriction<SimdReal>`).
//!
//! The contacts of a batch move no common body
//! ([`OrderedBatches`](super::ordered_batches::OrderedBatches)), so no two lanes write the same
//! velocities: the batch gathers its bodies' velocities, runs exactly the
//! scalar solver's arithmetic ([`ContactConstraint::solve`], whose module derives the rows) in
//! every lane, and scatters the velocities back. A lane whose contact has fewer points than the
//! batch's largest, and the padding lanes of a short batch, hold zero rows: their impulses come
//! out zero and change nothing, so no lane needs a mask. A side whose body is static and at
//! rest in every lane (the ground under resting bodies) is read as the rest state's constants,
//! not gathered nor scattered: rapier's one-body contact constraints, the same bits.
//!
//! [`ContactBatches`] keeps a step's batches densely, in the order the passes read them: the
//! batches' shared rows, then their points one after another (as many as each batch has, not
//! room for the most), their friction rows per point in a list of their own (only the relax
//! passes read them), or their friction per patch. What a lane holds, and why a point keeps no
//! lever arms, is in `batch_rows.rs`.
//!
//! The batches are packed from the prepared constraints once per step and their impulses
//! unpacked into them after the substeps, so restitution, warm-start storage and contact
//! reports read the constraints as before.

use super::anchor_drift::spreads_target;
use super::batch_rows::{FrictionX4, PatchX4, PointX4};
use super::body::BodyState;
use super::contact::{ConstraintPoint, ContactConstraint};
use super::lanes::{LANES, Lanes, PairVelocities, Quatx4, Slots, Vec3x4, lanes_of};
use super::patch_friction::PatchFriction;
use crate::geometry::MAX_MANIFOLD_POINTS;
use glam::Vec3;

/// What the lanes of one batch share in every pass: their bodies, directions and softness, and
/// where the batch's points lie in [`ContactBatches`] (which constraint each lane holds is kept
/// apart, in [`ContactBatches::members`]: only unpacking reads it).
#[derive(Clone, Debug)]
struct ContactBatch {
    /// Body slots of A and B per lane (padding lanes repeat lane 0's).
    bodies: Slots,
    /// Whether the lane writes A's and B's velocities back (dynamic bodies of real lanes).
    writes: [[bool; LANES]; 2],
    /// Whether every lane's A (B) is still ([`ContactConstraint::still`]): its state is then
    /// the rest state's constants, not gathered (a ground under resting bodies: the passes
    /// load one body per lane, and store one as for any side that writes no lane, as rapier's
    /// one-body contact constraints do).
    still: [bool; 2],
    normal: Vec3x4,
    tangents: [Vec3x4; 2],
    friction: Lanes,
    inverse_mass: [Lanes; 2],
    /// `mass_scale · bias_rate`, `mass_scale`, `impulse_scale` of each lane's softness.
    softness: [Lanes; 3],
    closing_acceleration: Lanes,
    /// Which lanes are impacts (all bits set; [`ContactConstraint::impact`]).
    impacts: Lanes,
    /// The batch's first point in [`ContactBatches::points`].
    first: u32,
    /// The most points any lane has: the batch's points in that list.
    count: u32,
    /// Where the batch's friction rows are: its points' first in
    /// [`ContactBatches::frictions`] (friction per point), or its entry in
    /// [`ContactBatches::patches`] (friction per patch).
    rows: FrictionRows,
    /// Whether any lane has friction.
    rubs: bool,
    /// Whether any lane's friction rows may have a drift target
    /// ([`ContactConstraint::turning`]): the others solve them without one.
    turns: bool,
    /// A's and B's rounding per lane ([`ContactConstraint::rounding`]; zero in a batch
    /// without a rounded side, which gathers none).
    rounding: [Lanes; 2],
    /// The lanes with an immovable side (all bits set), whose drift targets are spread over
    /// the substeps ([`spreads_target`]).
    carried: Lanes,
}

/// Where a batch's friction rows are ([`ContactBatch::rows`]).
#[derive(Clone, Copy, Debug)]
enum FrictionRows {
    /// Per point, from this index of [`ContactBatches::frictions`] on.
    PerPoint(u32),
    /// Per patch, at this index of [`ContactBatches::patches`].
    Patch(u32),
}

/// A step's contact batches, in solving order, stored densely (module docs).
#[derive(Clone, Debug, Default)]
pub struct ContactBatches {
    batches: Vec<ContactBatch>,
    /// Which constraint each lane of each batch holds (`None`: padding).
    members: Vec<[Option<u32>; LANES]>,
    points: Vec<PointX4>,
    /// Friction per point: the rows of the points of the batches that have them.
    frictions: Vec<FrictionX4>,
    /// Friction per patch: the batches' that have it.
    patches: Vec<PatchX4>,
}

impl ContactBatches {
    /// Packs each group of `indices` (1 to [`LANES`] constraints moving no common body) of
    /// `constraints` as one batch, in order, in place of what was held (the solver refills
    /// last step's lists: building each batch anew and moving it in copied it twice). False
    /// for a group with no index, more than [`LANES`] or an index out of range: the batches
    /// then hold the groups before it.
    pub fn pack<'a>(
        &mut self,
        groups: impl IntoIterator<Item = &'a [u32]>,
        constraints: &[ContactConstraint],
    ) -> bool {
        let mut filled = Filled::default();
        let mut packed = true;
        for indices in groups {
            if !self.push(&mut filled, indices, constraints) {
                packed = false;
                break;
            }
        }
        self.batches.truncate(filled.batches);
        self.members.truncate(filled.batches);
        self.points.truncate(filled.points);
        self.frictions.truncate(filled.frictions);
        self.patches.truncate(filled.patches);
        packed
    }

    /// How many batches are held.
    pub fn len(&self) -> usize {
        self.batches.len()
    }

    /// True when no batch is held.
    pub fn is_empty(&self) -> bool {
        self.batches.is_empty()
    }

    /// Writes the impulses and approach speeds back into the constraints the lanes came from.
    pub fn unpack(&self, constraints: &mut [ContactConstraint]) {
        for (batch, members) in self.batches.iter().zip(&self.members) {
            for (lane, index) in members.iter().enumerate() {
                let Some(index) = index else { continue };
                let c = &mut constraints[*index as usize];
                let mine = &mut c.points[..c.count as usize];
                for (point, wide) in mine.iter_mut().zip(self.points_of(batch)) {
                    wide.scatter(lane, point);
                }
                match batch.rows {
                    FrictionRows::PerPoint(from) => {
                        let frictions = &self.frictions[batch.range(from)];
                        for (point, wide) in mine.iter_mut().zip(frictions) {
                            wide.scatter(lane, point);
                        }
                    }
                    FrictionRows::Patch(at) => {
                        if let Some(patch) = &mut c.patch {
                            self.patches[at as usize].scatter(lane, patch);
                        }
                    }
                }
            }
        }
    }

    /// Takes the rows of the constraints `rebuilt` names (their bodies turned within the step,
    /// `turned_rows.rs`) into their lanes; friction per patch keeps the step's rows.
    pub fn refresh_rows(
        &mut self,
        constraints: &[ContactConstraint],
        rebuilt: impl Fn(usize) -> bool,
    ) {
        for (batch, members) in self.batches.iter().zip(&self.members) {
            for (lane, index) in members.iter().enumerate() {
                let Some(index) = index.filter(|&i| rebuilt(i as usize)) else {
                    continue;
                };
                let points = constraints[index as usize].points();
                let wide = &mut self.points[batch.range(batch.first)];
                for (wide, point) in wide.iter_mut().zip(points) {
                    wide.normal_row.set_lane(lane, &point.normal_row);
                }
                if let FrictionRows::PerPoint(from) = batch.rows {
                    let wide = &mut self.frictions[batch.range(from)];
                    for (wide, point) in wide.iter_mut().zip(points) {
                        wide.rows[0].set_lane(lane, &point.tangent_rows[0]);
                        wide.rows[1].set_lane(lane, &point.tangent_rows[1]);
                    }
                }
            }
        }
    }

    /// Applies the accumulated impulses ([`ContactConstraint::warm_start`] per lane).
    pub fn warm_start(&self, states: &mut [BodyState]) {
        for batch in &self.batches {
            let points = self.points_of(batch);
            let mut pair = PairVelocities::load(&batch.bodies, batch.still, states);
            let normal = |pair: &mut PairVelocities, p: &PointX4| {
                let turn = &p.normal_row.turn;
                pair.push(batch.inverse_mass, batch.normal, turn, p.normal_impulse);
            };
            match batch.rows {
                // Each point's normal, then its friction rows (the scalar rows' order).
                FrictionRows::PerPoint(from) => {
                    let frictions = &self.frictions[batch.range(from)];
                    for (p, f) in points.iter().zip(frictions) {
                        normal(&mut pair, p);
                        for k in 0..2 {
                            let (t, turn) = (batch.tangents[k], &f.rows[k].turn);
                            pair.push(batch.inverse_mass, t, turn, f.impulse[k]);
                        }
                    }
                }
                FrictionRows::Patch(at) => {
                    points.iter().for_each(|p| normal(&mut pair, p));
                    warm_start_patch(batch, &self.patches[at as usize], &mut pair);
                }
            }
            pair.store(&batch.bodies, &batch.writes, states);
        }
    }

    /// One pass over the batches ([`ContactConstraint::solve`] per lane; `flip` visits the
    /// points backwards): biased (push-out, normal rows only) or relaxing (no bias, friction
    /// aiming at `share` of its drift targets: `(2k + 1)/n` in substep `k` of `n` on a
    /// platform, `anchor_drift.rs`).
    pub fn solve(
        &mut self,
        states: &mut [BodyState],
        (inv_h, max_push_out): (f32, f32),
        use_bias: bool,
        flip: bool,
        share: f32,
    ) {
        let pass = Pass {
            inv_h,
            max_push_out,
            use_bias,
            flip,
        };
        for batch in &self.batches {
            let points = &mut self.points[batch.range(batch.first)];
            let mut pair = PairVelocities::load(&batch.bodies, batch.still, states);
            solve_normals(batch, points, &mut pair, states, &pass);
            if !use_bias && batch.rubs {
                match batch.rows {
                    FrictionRows::PerPoint(from) => {
                        let frictions = &mut self.frictions[batch.range(from)];
                        if batch.turns {
                            solve_friction::<true>(batch, points, frictions, &mut pair, share);
                        } else {
                            solve_friction::<false>(batch, points, frictions, &mut pair, share);
                        }
                    }
                    FrictionRows::Patch(at) => {
                        let patch = &mut self.patches[at as usize];
                        solve_patch(batch, points, patch, &mut pair, share);
                    }
                }
            }
            pair.store(&batch.bodies, &batch.writes, states);
        }
    }

    /// The points of `batch`.
    fn points_of(&self, batch: &ContactBatch) -> &[PointX4] {
        &self.points[batch.range(batch.first)]
    }

    /// Packs `indices` as the next batch at the lists' `filled` ends, overwriting what lies
    /// there (module docs).
    fn push(
        &mut self,
        filled: &mut Filled,
        indices: &[u32],
        constraints: &[ContactConstraint],
    ) -> bool {
        let Some((lanes, first)) = lanes_of(indices, constraints) else {
            return false;
        };
        let count = lanes
            .iter()
            .flatten()
            .map(|c| c.count as usize)
            .max()
            .unwrap_or(0);
        debug_assert!(
            count <= MAX_MANIFOLD_POINTS,
            "prepare caps a contact's points"
        );
        let patched = lanes.iter().flatten().any(|c| c.patch.is_some());
        let rows = if patched {
            FrictionRows::Patch(filled.patches as u32)
        } else {
            FrictionRows::PerPoint(filled.frictions as u32)
        };
        let header = ContactBatch::packed(lanes, first, (filled.points as u32, count as u32), rows);
        put(&mut self.batches, filled.batches, header);
        put(
            &mut self.members,
            filled.batches,
            std::array::from_fn(|l| indices.get(l).copied()),
        );
        filled.batches += 1;
        let zero = ConstraintPoint::default();
        let lane_points = |k: usize| {
            std::array::from_fn(|l| match lanes[l] {
                Some(c) if k < c.count as usize => &c.points[k],
                _ => &zero,
            })
        };
        let still = lanes.map(|c| c.map_or([false; 2], |c| c.still));
        for k in 0..count {
            let points = lane_points(k);
            put(
                &mut self.points,
                filled.points + k,
                PointX4::gather(points, still),
            );
            if !patched {
                put(
                    &mut self.frictions,
                    filled.frictions + k,
                    FrictionX4::gather(points),
                );
            }
        }
        filled.points += count;
        if patched {
            let none = PatchFriction::default();
            let patches = lanes.map(|c| c.and_then(|c| c.patch.as_ref()).unwrap_or(&none));
            put(&mut self.patches, filled.patches, PatchX4::gather(patches));
            filled.patches += 1;
        } else {
            filled.frictions += count;
        }
        true
    }
}

/// How far [`ContactBatches::pack`] has filled each list.
#[derive(Default)]
struct Filled {
    batches: usize,
    points: usize,
    frictions: usize,
    patches: usize,
}

/// Writes `value` at `at` (overwriting, or appending at the end).
fn put<T>(list: &mut Vec<T>, at: usize, value: T) {
    match list.get_mut(at) {
        Some(slot) => *slot = value,
        None => list.push(value),
    }
}

/// What a pass over the batches is.
struct Pass {
    inv_h: f32,
    max_push_out: f32,
    use_bias: bool,
    flip: bool,
}

impl ContactBatch {
    /// The batch's `count` entries of a list from index `from` on (its points, or its points'
    /// friction rows).
    fn range(&self, from: u32) -> std::ops::Range<usize> {
        from as usize..(from + self.count) as usize
    }

    /// The shared rows of the constraints `lanes` (`first` is lane 0's),
    /// their `count` points from `first_point` on, their friction `rows`.
    fn packed(
        lanes: [Option<&ContactConstraint>; LANES],
        first: &ContactConstraint,
        (first_point, count): (u32, u32),
        rows: FrictionRows,
    ) -> Self {
        let real = |l: usize| lanes[l].unwrap_or(first);
        let each = |f: fn(&ContactConstraint) -> f32| {
            Lanes::new(std::array::from_fn(|l| lanes[l].map_or(0.0, f)))
        };
        let vectors = |f: fn(&ContactConstraint) -> Vec3| {
            Vec3x4::gather(std::array::from_fn(|l| lanes[l].map_or(Vec3::ZERO, f)))
        };
        debug_assert!(
            lanes.iter().flatten().all(|c| !c.translation_locked),
            "contacts of a body locked along some translation axes are solved one at a time"
        );
        let turns = lanes.iter().flatten().any(|c| c.turning);
        let rolls = lanes.iter().flatten().any(|c| c.rounding != [0.0; 2]);
        Self {
            bodies: [
                std::array::from_fn(|l| real(l).a),
                std::array::from_fn(|l| real(l).b),
            ],
            writes: [0, 1].map(|k| std::array::from_fn(|l| lanes[l].is_some_and(|c| c.dynamic[k]))),
            still: [0, 1].map(|k| lanes.iter().flatten().all(|c| c.still[k])),
            normal: vectors(|c| c.normal),
            tangents: [vectors(|c| c.tangents[0]), vectors(|c| c.tangents[1])],
            friction: each(|c| c.friction),
            inverse_mass: [each(|c| c.inverse_mass[0].x), each(|c| c.inverse_mass[1].x)],
            softness: [
                each(|c| c.softness.mass_scale * c.softness.bias_rate),
                each(|c| c.softness.mass_scale),
                each(|c| c.softness.impulse_scale),
            ],
            closing_acceleration: each(|c| c.closing_acceleration),
            impacts: each(|c| f32::from(u8::from(c.impact))).simd_gt(Lanes::ZERO),
            first: first_point,
            count,
            rows,
            rubs: lanes.iter().flatten().any(|c| c.friction > 0.0),
            turns,
            rounding: match rolls {
                true => [each(|c| c.rounding[0]), each(|c| c.rounding[1])],
                false => [Lanes::ZERO; 2],
            },
            carried: match turns {
                true => each(|c| f32::from(u8::from(spreads_target(c.dynamic)))),
                false => Lanes::ZERO,
            }
            .simd_gt(Lanes::ZERO),
        }
    }
}

/// The warm start of a patch's friction (out of line, as [`solve_patch`]).
#[inline(never)]
fn warm_start_patch(batch: &ContactBatch, patch: &PatchX4, pair: &mut PairVelocities) {
    for k in 0..2 {
        let (t, row) = (batch.tangents[k], &patch.tangent_rows[k]);
        pair.push(batch.inverse_mass, t, &row.turn, patch.tangent_impulse[k]);
    }
    pair.twist(patch, patch.twist_impulse);
}

/// Coulomb friction at each point: both tangent rows clamped together to the disc `μ λ_n`,
/// with their drift targets when `DRIFT` (a batch none of whose lanes turns has none, and
/// does not read them).
fn solve_friction<const DRIFT: bool>(
    batch: &ContactBatch,
    points: &[PointX4],
    frictions: &mut [FrictionX4],
    pair: &mut PairVelocities,
    share: f32,
) {
    let zero = Lanes::ZERO;
    let share = if DRIFT {
        batch.carried.select(Lanes::splat(share), Lanes::ONE)
    } else {
        Lanes::ONE
    };
    for (p, f) in points.iter().zip(frictions) {
        let [old0, old1] = f.impulse;
        let idle = p.normal_impulse.simd_eq(zero) & old0.simd_eq(zero) & old1.simd_eq(zero);
        if idle.all() {
            continue;
        }
        let limit = batch.friction * p.normal_impulse;
        // Written out, not `[0, 1].map(..)` (see `Vec3x4::gather`).
        let rows = [
            p.row(&f.rows[0], batch.tangents[0]),
            p.row(&f.rows[1], batch.tangents[1]),
        ];
        f.impulse = pair.solve_disc::<DRIFT>(
            &rows,
            batch.tangents,
            (f.impulse, f.drift, share),
            (limit, batch.inverse_mass),
        );
    }
}

/// Friction per patch ([`PatchFriction`]): the twist, then the tangent disc at the centre,
/// within `μ Σλ_i d_i` and `μ Σλ_i`. Kept out of line: inlined, it changed how the per-point
/// passes were compiled (+4 % instructions on a pyramid).
#[inline(never)]
fn solve_patch(
    batch: &ContactBatch,
    points: &[PointX4],
    patch: &mut PatchX4,
    pair: &mut PairVelocities,
    share: f32,
) {
    let zero = Lanes::ZERO;
    let (mut sum, mut moment) = (zero, zero);
    for (p, arm) in points.iter().zip(patch.arms) {
        sum += p.normal_impulse;
        moment += p.normal_impulse * arm;
    }
    let (limit, twist_limit) = (batch.friction * sum, batch.friction * moment);
    let old = patch.twist_impulse;
    let [old0, old1] = patch.tangent_impulse;
    let idle = limit.simd_eq(zero) & old.simd_eq(zero) & old0.simd_eq(zero) & old1.simd_eq(zero);
    if idle.all() {
        return;
    }
    let wanted = old - patch.twist_mass * batch.normal.dot(pair.wb - pair.wa);
    let twist = wanted.max(-twist_limit).min(twist_limit);
    pair.twist(patch, twist - old);
    patch.twist_impulse = twist;
    let rows = patch.tangent_rows;
    let share = batch.carried.select(Lanes::splat(share), Lanes::ONE);
    patch.tangent_impulse = pair.solve_disc::<true>(
        &rows,
        batch.tangents,
        (patch.tangent_impulse, patch.tangent_drift, share),
        (limit, batch.inverse_mass),
    );
}

#[path = "batch_normals.rs"]
mod normals;
use normals::solve_normals;

#[cfg(test)]
#[path = "batch_tests.rs"]
mod tests;
