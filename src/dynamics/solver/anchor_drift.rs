//! What friction at anchors fixed for a step misses when the bodies turn: the second-order
//! drift of two material points held together, and the friction rows' target that removes it.
//!
//! # Why
//! A contact's anchors `r_a`, `r_b` are taken once per step (Box2D v3), and friction drives the
//! tangential relative velocity at them, `J V = t·(v_b + ω_b × r_b − v_a − ω_a × r_a)`, to
//! zero. A box on a turntable then moves for the whole step along the tangent of the point of
//! the table under it at the step's start, while that point moves along an arc: the box ends
//! `ω² ρ h² / 2` further out every step (`h` the step), 1.8 cm/s at 2 m from the axis at
//! 1 rad/s and 60 Hz, and walks off the table.
//!
//! # The target
//! Two material points held together stay together over the step when their *mean* relative
//! velocity over it is zero. With `v` and `ω` constant over the step a material point's anchor
//! turns, `ṙ = ω × r`, so
//!
//! `d(J V)/dt = t·(ω_b × (ω_b × r_b) − ω_a × (ω_a × r_a))`,
//!
//! and the mean over the step is `J V + (h/2) d(J V)/dt`. Each friction row therefore solves
//! `J V + drift = 0` with `drift = (h/2) t·(T_b − T_a)`, `T = ω × (ω × r)` in the contact
//! plane: the box on the turntable gets the inward velocity `ω² ρ h/2` that carries it along
//! the chord, and stays on its circle.
//!
//! # Which turn
//! Only the spin about the normal is followed: `T = −(ω·n)² r_∥`, `r_∥ = r − (r·n) n` the
//! anchor's part in the contact plane. A body's roll (its turn about an axis in the plane) does
//! not carry its contact along as a material point when the body is round: a ball's contact
//! stays below its centre however it rolls, and a cylinder rolling across a tessellated floor
//! has points ahead of its axis. Turned as material points they gave a ball rolling with spin
//! a sideways target (0.4 m/s at 10 rad/s of each) and sent the cylinder 11 cm off its line in
//! 10 m. The spin about the normal moves a sticking contact with the spinning body whatever
//! its shape (a ball spinning in place has `r_∥ = 0`), and it is the turn of a platform, a
//! turntable or a carousel. For the box on the turntable the target is exact: `T_b − T_a =
//! ω² (c_b − c_a)_∥`, the centripetal velocity change of the box's centre.
//!
//! # Rolling contacts
//! A ball rolling on a turntable keeps its contact under its centre, so the contact point
//! moves across the table at the ball's velocity, not with the table's material point under
//! it: what friction holds at zero over the step is the relative velocity at a point `p(t)`
//! that moves at `ṗ`, and a body's velocity there changes at `T = ω × (ṗ − v)` (`v` its centre
//! of mass's velocity), which for a material point (`ṗ − v = ω × r`) is the `T` above. A
//! rounded body (a ball, a capsule: [`Shape::rounding`](crate::geometry::Shape::rounding)
//! `ρ`, its surface the points `ρ` from its core) touches at its core's point `C = r + ρ n`
//! (B's side; `r − ρ n` on A's) plus `ρ` along the normal however it turns, so the contact
//! moves with that core point, a material one: `ṗ = v + ω × C`. Against a shape without
//! rounding (taken as flat there) the contact follows the rounded body's core; between two
//! rounded bodies it lies between the cores, `ṗ = (ρ_b Ċ_a + ρ_a Ċ_b)/(ρ_a + ρ_b)`. Both
//! sides then take `T = (ω·n) n × (ṗ − v)`. A solid ball rolling round a table at Ω orbits
//! its axis at `2Ω/7` (`v̇ = (I/(I + m R²)) Ω × v`), and its target is 2/7 of a riding box's;
//! taken as a point of the table it moved inward 3.4 mm/s at 2 m and 1 rad/s. Shapes without
//! rounding keep both sides' points material (a cylinder standing on its cap turns its rim
//! points with it; one rolling on its side is not followed).
//!
//! # Across substeps
//! The target is the step's: its mean over the step is what keeps the points on their arc.
//! Aimed at in full in every substep it asks friction to turn the body's velocity by the
//! whole step's turn in the first substep, where a substep's friction can give a substep's
//! share of it: a box on a turntable needing more than a quarter of its friction (at 4
//! substeps) slid, 13.5 mm in 8 s at 2 m and 1 rad/s, 5.8 cm at 3 m, more with more
//! substeps. Substep `k` of `n` aims at [`drift_share`] `(2k + 1)/n` of it instead: the same
//! mean over the step, and a velocity that turns by one substep's share from each substep to
//! the next, across steps too (0.03 mm in both scenes). Between two dynamic bodies the whole
//! target is aimed at from the first substep ([`contact_share`]): friction spread over the
//! substeps at anchors held for the step acts on each body at its own anchor, and the two
//! part as the bodies move, a couple that turned a free disc carrying a box 0.73 % faster in
//! 10 s; turned once at the first substep and held, the couple cancels over the step.
//!
//! # Sticking only
//! The target holds material points together, so it applies while the contact sticks: a point
//! that slips at the step's start much faster than its target ([`STICKING_SLIP`]) slides as
//! before, along its relative velocity alone. Its friction impulse acts at the anchor of the
//! step's start, where the target would only tilt it off the slip (a box spun on the ground
//! at 20 rad/s slowed 3.2 % less than Coulomb's law predicts with it, 1.4 % without, as
//! before the targets). Whether a point sticks is read from its slip, not from its friction
//! disc: a point held at its target is always a target's width from the answer without it,
//! and the corners of a box on a turntable touch their discs' edges, by turns, in most
//! substeps. Bodies that do not spin about the normal, or spin slower than [`SPIN_FLOOR`], get
//! no target, so a scene without rotation solves exactly the rows it solved before.

use super::body::BodyState;
use super::contact::point_velocity;
use glam::Vec3;

/// Spins about the normal slower than this (rad/s) get no target. The drift they would
/// correct, `ω² ρ h² / 2` a step, is 1.4e-8 m per metre of `ρ` at 0.01 rad/s and 60 Hz, below
/// the float spacing of a position a metre from the origin (6e-8 m): solving it adds only
/// rounding, and a tall stack's sway answers rounding chaotically (the 20-box stack of
/// `scenarios.rs` drifted 7.3 mm in 10 s without targets, 9.2–10.6 mm with targets for
/// spins of 1e-5 to 1e-3 rad/s, and 7.3 mm again from a floor of 3e-3 rad/s up).
pub(super) const SPIN_FLOOR: f32 = 0.01;

/// A point slipping at up to this many times its drift target's size at the step's start
/// sticks (the target in full), and one slipping at twice that slides (no target), with a
/// linear fade between. A point held at its target last step slips at about the target's size
/// (its chord's velocity against the tangent at the step's end); one sliding on a body that
/// spins at `ω` slips at `1/(ω h/2)` times it (6 at 20 rad/s and 60 Hz).
const STICKING_SLIP: f32 = 2.0;

/// The share of a step's drift target that the friction rows aim at in substep `k` of `n`,
/// `(2k + 1)/n` (module docs, *Across substeps*): their mean over the step is 1, and from one
/// substep to the next, across steps too, it grows by one substep's turn.
#[inline]
pub(super) fn drift_share(k: u32, n: u32) -> f32 {
    (2 * k + 1) as f32 / n.max(1) as f32
}

/// The share a contact between bodies that are `dynamic` aims at in a substep whose
/// [`drift_share`] is `share`: that share on an immovable body (a platform), the whole target
/// from the first substep between two dynamic bodies (module docs, *Across substeps*).
#[inline]
pub(super) fn contact_share(dynamic: [bool; 2], share: f32) -> f32 {
    if spreads_target(dynamic) { share } else { 1.0 }
}

/// Whether a contact between bodies that are `dynamic` spreads its drift target over the
/// substeps: when one of them is immovable ([`contact_share`]).
#[inline]
pub(super) fn spreads_target(dynamic: [bool; 2]) -> bool {
    !(dynamic[0] && dynamic[1])
}

/// The friction targets of one contact's points (module docs), taken once per step.
#[derive(Clone, Copy, Debug)]
pub(super) struct AnchorDrift<'a> {
    /// A's and B's states at the step's start.
    states: [&'a BodyState; 2],
    /// `ω·n` of A and B: their spins about the normal.
    spins: [f32; 2],
    /// A's and B's rounding ([`ContactInput::rounding`](super::ContactInput::rounding)).
    rounding: [f32; 2],
    normal: Vec3,
    tangents: [Vec3; 2],
    /// Half the step (`h/2`).
    half_step: f32,
}

impl<'a> AnchorDrift<'a> {
    /// The targets of a contact of normal `normal` and friction directions `tangents` between
    /// bodies in `states` (A, B), over a step of `step` seconds; `None` when neither body
    /// spins about the normal as fast as [`SPIN_FLOOR`] (every target zero), or `step` is not
    /// a positive finite duration (`RowSettings` is public: a negative step would aim the
    /// targets outward).
    #[inline]
    pub fn new(
        states: [&'a BodyState; 2],
        (normal, tangents): (Vec3, [Vec3; 2]),
        rounding: [f32; 2],
        step: f32,
    ) -> Option<Self> {
        let spins = [
            states[0].angular_velocity.dot(normal),
            states[1].angular_velocity.dot(normal),
        ];
        let turning = spins[0].abs() >= SPIN_FLOOR || spins[1].abs() >= SPIN_FLOOR;
        let usable = step > 0.0 && step.is_finite();
        (turning && usable).then_some(Self {
            states,
            spins,
            rounding,
            normal,
            tangents,
            half_step: 0.5 * step,
        })
    }

    /// The velocity of B's point at `rb` relative to A's at `ra` (for a point whose caller
    /// has not taken it already).
    pub fn relative(&self, ra: Vec3, rb: Vec3) -> Vec3 {
        point_velocity(self.states[1], rb) - point_velocity(self.states[0], ra)
    }

    /// `(h/2) t_k·(T_b − T_a)` along each tangent for the anchors `ra`, `rb`, whose points move
    /// at `relative` ([`Self::relative`]), in full while the point sticks and faded out as it
    /// slides (module docs); zero where the product overflows (a hostile spin) rather than an
    /// infinity.
    pub fn at(&self, ra: Vec3, rb: Vec3, relative: Vec3) -> [f32; 2] {
        let n = self.normal;
        let in_plane = |v: Vec3| v - n * n.dot(v);
        let change = match self.contact_motion([ra, rb]) {
            Some(motion) => self.follow(1, motion) - self.follow(0, motion),
            None => self.turn(1, rb) - self.turn(0, ra),
        } * self.half_step;
        let reach = change.length();
        if reach == 0.0 || !reach.is_finite() {
            // The two anchors turn alike (the point on the axis of both), or overflowed.
            return [0.0; 2];
        }
        let slip = in_plane(relative).length();
        let hold = ((STICKING_SLIP * 2.0 * reach - slip) / (STICKING_SLIP * reach)).clamp(0.0, 1.0);
        let [t0, t1] = self.tangents;
        let drift = [t0.dot(change) * hold, t1.dot(change) * hold];
        if drift.iter().all(|d| d.is_finite()) {
            drift
        } else {
            [0.0; 2]
        }
    }

    /// `T` of side `x` (0: A, 1: B) at its material point `r`: `−(ω·n)² r_∥`.
    #[inline]
    fn turn(&self, x: usize, r: Vec3) -> Vec3 {
        let (n, spin) = (self.normal, self.spins[x]);
        (r - n * n.dot(r)) * (-spin * spin)
    }

    /// `T` of side `x` at a contact point moving at `motion`: `(ω·n) n × (ṗ − v)`.
    #[inline]
    fn follow(&self, x: usize, motion: Vec3) -> Vec3 {
        let n = self.normal;
        n.cross(motion - self.states[x].linear_velocity) * self.spins[x]
    }

    /// `ṗ`, the velocity of the contact point at the anchors `r` when a side is rounded: the
    /// rounded side's core point's, or between two rounded sides the point between them
    /// (module docs); `None` when neither is (both points material).
    #[inline]
    fn contact_motion(&self, r: [Vec3; 2]) -> Option<Vec3> {
        let [rho_a, rho_b] = self.rounding;
        if rho_a == 0.0 && rho_b == 0.0 {
            return None;
        }
        let n = self.normal;
        let core = |x: usize, c: Vec3| point_velocity(self.states[x], c);
        let (core_a, core_b) = (|| core(0, r[0] - n * rho_a), || core(1, r[1] + n * rho_b));
        Some(if rho_a == 0.0 {
            core_b()
        } else if rho_b == 0.0 {
            core_a()
        } else {
            (core_a() * rho_b + core_b() * rho_a) / (rho_a + rho_b)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const HALF: f32 = 1.0 / 120.0;

    /// A body state moving at `v`, turning at `w`.
    fn state(v: Vec3, w: Vec3) -> BodyState {
        BodyState {
            linear_velocity: v,
            angular_velocity: w,
            ..Default::default()
        }
    }

    /// The targets at `ra`, `rb` between bodies in `states` over a step of `2 HALF`, across
    /// normal `n`, each side's point material.
    fn targets(states: [BodyState; 2], ra: Vec3, rb: Vec3) -> Vec3 {
        targets_of(states, (Vec3::Z, [0.0; 2]), ra, rb)
    }

    /// [`targets`] across normal `n`, the sides rounded by `rounding`.
    fn targets_of(
        states: [BodyState; 2],
        (n, rounding): (Vec3, [f32; 2]),
        ra: Vec3,
        rb: Vec3,
    ) -> Vec3 {
        let tangents = [Vec3::X, Vec3::Y];
        let d = AnchorDrift::new(
            [&states[0], &states[1]],
            (n, tangents),
            rounding,
            2.0 * HALF,
        );
        let [x, y] = d.map_or([0.0; 2], |d| d.at(ra, rb, d.relative(ra, rb)));
        Vec3::new(x, y, 0.0)
    }

    /// The targets for bodies spinning at `spins`, their centres moving so that the point
    /// `ra`, `rb` sticks (the slip is zero).
    fn drift(spins: [Vec3; 2], ra: Vec3, rb: Vec3) -> Vec3 {
        let b = state(spins[0].cross(ra) - spins[1].cross(rb), spins[1]);
        targets([state(Vec3::ZERO, spins[0]), b], ra, rb)
    }

    #[test]
    fn a_box_on_a_turntable_is_sent_inward_at_omega_squared_rho_half_step_within_1e_6() {
        // Table at the origin turning at 1 rad/s; the box 2 m out, turning with it, its
        // corner 0.5 m off its centre.
        let spin = Vec3::Z;
        let point = Vec3::new(2.5, 0.5, 0.0);
        let (ca, cb) = (Vec3::new(0.0, 0.0, -0.25), Vec3::new(2.0, 0.0, 0.5));
        let d = drift([spin, spin], point - ca, point - cb);
        // J V = −drift: the box's points move inward, along −x, at ω² ρ h/2.
        let expected = Vec3::new(2.0, 0.0, 0.0) * HALF;
        assert!((d - expected).length() < 1e-6, "{d}");
    }

    #[test]
    fn a_ball_rolling_round_a_turntable_at_two_sevenths_its_rate_gets_two_sevenths_of_a_box_target_within_1e_6()
     {
        // Table at the origin turning at 1 rad/s; a ball of radius 0.5 on it, 2 m out,
        // rolling without slip on its circle at 2/7 rad/s (its centre's velocity turns at
        // 2/7 Ω: `v̇ = (I/(I + m R²)) Ω × v`).
        let (table, ball) = (Vec3::new(0.0, 0.0, -0.25), Vec3::new(2.0, 0.0, 0.5));
        let point = Vec3::new(2.0, 0.0, 0.0);
        let (ra, rb) = (point - table, point - ball);
        let v = Vec3::Z.cross(ball) * (2.0 / 7.0);
        // Its roll makes its contact point move with the table's point under it.
        let roll = Vec3::new(20.0 / 7.0, 0.0, 0.0);
        let states = [state(Vec3::ZERO, Vec3::Z), state(v, roll)];
        let sticks = states[1].linear_velocity + roll.cross(rb) - Vec3::Z.cross(ra);
        assert!(sticks.length() < 1e-6, "{sticks}");
        let d = targets_of(states, (Vec3::Z, [0.0, 0.5]), ra, rb);
        // A box riding there gets ω² ρ h/2 inward; the rolling ball's contact turns at 2/7.
        let expected = Vec3::new(2.0, 0.0, 0.0) * (HALF * 2.0 / 7.0);
        assert!((d - expected).length() < 1e-6, "{d}");
        // The same pair listed the other way round: the same motion, the opposite rows.
        let swapped = targets_of([states[1], states[0]], (-Vec3::Z, [0.5, 0.0]), rb, ra);
        assert!((swapped + expected).length() < 1e-6, "{swapped}");
        // Taken as material points, the table's would be the box's: 7/2 times too far in.
        let material = targets(states, ra, rb);
        assert!((material - expected * 3.5).length() < 1e-6, "{material}");
    }

    #[test]
    fn substep_shares_average_one_and_grow_by_two_over_n_from_substep_to_substep_and_step_to_step_within_1e_6()
     {
        for n in [1, 2, 3, 4, 8, 16] {
            let shares: Vec<f32> = (0..n).map(|k| drift_share(k, n)).collect();
            let mean = shares.iter().sum::<f32>() / n as f32;
            assert!((mean - 1.0).abs() < 1e-6, "{n} substeps: mean {mean}");
            let step = 2.0 / n as f32;
            for pair in shares.windows(2) {
                assert!(
                    (pair[1] - pair[0] - step).abs() < 1e-6,
                    "{n} substeps: {shares:?}"
                );
            }
            // The next step's anchors are a whole step's turn (2 shares of h/2 each) ahead.
            let across = shares[0] + 2.0 - shares[n as usize - 1];
            assert!(
                (across - step).abs() < 1e-6,
                "{n} substeps: {across} across steps"
            );
        }
        assert_eq!(contact_share([true, true], 0.25), 1.0);
        assert_eq!(contact_share([true, false], 0.25), 0.25);
        assert_eq!(contact_share([false, false], 1.75), 1.75);
    }

    #[test]
    fn a_ball_rolling_on_another_rounded_body_follows_the_point_between_their_cores_within_1e_6() {
        // Two balls of radii 1 and 3 touching along z, each moving and turning: the contact
        // lies a quarter of the way from A's centre to B's, and moves so.
        let (ra, rb) = (Vec3::Z, Vec3::NEG_Z * 3.0);
        let [a, b] = [
            state(Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.3, -0.2, 2.0)),
            state(Vec3::new(0.0, 2.0, 0.0), Vec3::new(-0.5, 0.1, -1.0)),
        ];
        let drift = AnchorDrift::new([&a, &b], (Vec3::Z, [Vec3::X, Vec3::Y]), [1.0, 3.0], 0.1);
        let Some(drift) = drift else {
            panic!("the balls spin about the normal");
        };
        let motion = drift.contact_motion([ra, rb]);
        let expected = a.linear_velocity * 0.75 + b.linear_velocity * 0.25;
        assert!(
            motion.is_some_and(|m| (m - expected).length() < 1e-6),
            "{motion:?}"
        );
    }

    #[test]
    fn a_ball_rolling_with_spin_about_the_normal_on_still_ground_gets_no_target_within_1e_9() {
        let spin = Vec3::new(0.0, 10.0, 10.0);
        let d = drift(
            [Vec3::ZERO, spin],
            Vec3::new(3.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, -0.5),
        );
        assert!(d.length() < 1e-9, "{d}");
    }

    #[test]
    fn a_roll_gets_no_target_and_a_tilted_spin_only_its_part_about_the_normal_within_1e_6() {
        // A cylinder rolling about +y with a point 0.2 m ahead of its axis.
        let rolling = drift(
            [Vec3::ZERO, Vec3::Y * 6.0],
            Vec3::ZERO,
            Vec3::new(0.2, 0.4, -0.5),
        );
        assert!(rolling.length() < 1e-9, "{rolling}");
        // Spin (0, 3, 2): only its 2 rad/s about the normal moves the anchor.
        let d = drift(
            [Vec3::ZERO, Vec3::new(0.0, 3.0, 2.0)],
            Vec3::ZERO,
            Vec3::new(0.5, 0.3, -0.5),
        );
        let expected = Vec3::new(0.5, 0.3, 0.0) * (-4.0 * HALF);
        assert!((d - expected).length() < 1e-6, "{d}");
    }

    #[test]
    fn a_point_slipping_past_twice_the_sticking_slip_gets_none_and_half_way_half_within_1e_6() {
        let (spin, ra, rb) = (
            Vec3::Z,
            Vec3::new(2.5, 0.5, 0.25),
            Vec3::new(0.5, 0.5, -0.5),
        );
        let full = drift([spin, spin], ra, rb);
        let reach = full.length();
        let at_slip = |slip: f32| {
            let vb = spin.cross(ra) - spin.cross(rb) + Vec3::Y * slip;
            targets([state(Vec3::ZERO, spin), state(vb, spin)], ra, rb)
        };
        assert!((at_slip(STICKING_SLIP * reach) - full).length() < 1e-6);
        assert!((at_slip(1.5 * STICKING_SLIP * reach) - full * 0.5).length() < 1e-6);
        assert_eq!(at_slip(2.01 * STICKING_SLIP * reach), Vec3::ZERO);
    }

    #[test]
    fn a_step_that_is_not_a_positive_finite_duration_gives_no_targets() {
        let (a, b) = (state(Vec3::ZERO, Vec3::Z), state(Vec3::Y * 2.0, Vec3::Z));
        for step in [0.0, -1.0 / 60.0, f32::NAN, f32::INFINITY] {
            let d = AnchorDrift::new([&a, &b], (Vec3::Z, [Vec3::X, Vec3::Y]), [0.0; 2], step);
            assert!(d.is_none(), "a step of {step} s gave targets");
        }
        assert!(
            AnchorDrift::new(
                [&a, &b],
                (Vec3::Z, [Vec3::X, Vec3::Y]),
                [0.0; 2],
                1.0 / 60.0
            )
            .is_some()
        );
    }

    #[test]
    fn bodies_spinning_under_the_floor_get_exactly_zero_and_an_overflowing_spin_gets_zero() {
        let r = Vec3::new(1.0, 2.0, 3.0);
        assert_eq!(drift([Vec3::ZERO; 2], r, -r), Vec3::ZERO);
        let slow = Vec3::new(5.0, 0.0, 0.99 * SPIN_FLOOR);
        assert_eq!(drift([slow, -slow], r, -r), Vec3::ZERO);
        assert_ne!(drift([slow * 1.02, -slow], r, -r), Vec3::ZERO);
        let wild = Vec3::new(0.0, 0.0, 1e30);
        assert_eq!(drift([wild, Vec3::ZERO], r, -r), Vec3::ZERO);
    }
}
