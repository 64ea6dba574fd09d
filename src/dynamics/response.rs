//! Collision response: velocity impulses along contact normals and position correction.
//!
//! The slides' response is the reflection `v' = v - 2(v·N)N` of a velocity on a static surface.
//! Generalised with a coefficient of restitution `e` it becomes `v' = v - (1+e)(v·N)N`, and
//! between two movable bodies it becomes an impulse `j` along `N` shared by inverse mass, which
//! conserves momentum and, for `e = 1`, kinetic energy:
//!
//! `j = -(1+e) (v_b - v_a)·N / (1/m_a + 1/m_b)`, `v_a -= j N / m_a`, `v_b += j N / m_b`.
//!
//! With many simultaneous contacts (stacks, piles) single impulses fight each other, so contacts
//! are solved by sequential impulses with an accumulated, clamped impulse per contact (Catto,
//! "Iterative Dynamics with Temporal Coherence", GDC 2005): a few Gauss–Seidel sweeps converge to
//! the impulses that stop all approach at once, started from the previous step's impulses of the
//! same contact (warm starting) so that stacks and heavy loads stay supported. Coulomb friction
//! bounds the tangential impulse by `μ ×` the normal one (the same paper's friction disc). Penetration left by the discrete step is removed
//! by moving positions directly (no added velocity, so resting bodies neither sink nor jitter).
//! Response is linear: contacts push through the centre of mass (exact for spheres; boxes do not
//! spin from contacts).

use glam::Vec3;

/// The slides' reflection with restitution `e` about unit normal `n`: only the velocity
/// component *into* the surface (`v·n < 0`) is reflected and scaled by `e`.
pub fn reflect(v: Vec3, n: Vec3, e: f32) -> Vec3 {
    let vn = v.dot(n);
    if vn < 0.0 { v - (1.0 + e) * vn * n } else { v }
}

/// Most sweeps of either kind a step runs, whatever the settings ask: `u32::MAX` sweeps would
/// hang the step, and past a few hundred more sweeps change nothing.
pub const MAX_ITERATIONS: u32 = 256;

/// Tunables of the contact solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// Gauss–Seidel sweeps over the velocity constraints (at most [`MAX_ITERATIONS`] are run).
    pub velocity_iterations: u32,
    /// Sweeps of direct position correction (at most [`MAX_ITERATIONS`] are run).
    pub position_iterations: u32,
    /// Approach speeds below this (m/s) bounce with `e = 0`, so resting contact stays at rest
    /// instead of micro-bouncing on the velocity gravity adds every step.
    pub restitution_threshold: f32,
    /// Penetration tolerated without correction (m); keeps contacts alive between steps.
    pub slop: f32,
    /// Fraction of the remaining penetration removed per position sweep (0..=1).
    pub correction_fraction: f32,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            velocity_iterations: 8,
            position_iterations: 4,
            restitution_threshold: 0.5,
            slop: 0.002,
            correction_fraction: 0.8,
        }
    }
}

/// One contact between body `a` and body `b` (indices into the solver's arrays).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactConstraint {
    /// First body.
    pub a: usize,
    /// Second body.
    pub b: usize,
    /// Unit normal from `a` to `b`.
    pub normal: Vec3,
    /// Penetration depth at detection, `>= 0`.
    pub depth: f32,
    /// Coefficient of restitution of the pair.
    pub restitution: f32,
    /// Coulomb friction coefficient of the pair: the tangential impulse is at most
    /// `friction × normal impulse`.
    pub friction: f32,
    /// The caller's tag, carried through [`SupportGraph::order`]'s sorting (e.g. an index into
    /// the caller's own per-contact data).
    pub tag: u32,
    /// Separation speed the solver aims for (from restitution), set by [`prepare`](Self::prepare).
    target_speed: f32,
    /// Normal impulse accumulated over the sweeps (`>= 0`: contacts push, never pull).
    normal_impulse: f32,
    /// True when the approach was too slow to bounce: a body resting on, or pressed against,
    /// another.
    resting: bool,
    /// Friction impulse accumulated over the sweeps, in the contact's tangent plane.
    tangent_impulse: Vec3,
}

impl ContactConstraint {
    /// A frictionless contact from detection data.
    pub fn new(a: usize, b: usize, normal: Vec3, depth: f32, restitution: f32) -> Self {
        Self {
            a,
            b,
            normal,
            depth,
            restitution,
            friction: 0.0,
            tag: 0,
            target_speed: 0.0,
            normal_impulse: 0.0,
            resting: false,
            tangent_impulse: Vec3::ZERO,
        }
    }

    /// The same contact with the caller's tag.
    #[must_use]
    pub fn with_tag(mut self, tag: u32) -> Self {
        self.tag = tag;
        self
    }

    /// The same contact with Coulomb friction `mu`.
    #[must_use]
    pub fn with_friction(mut self, mu: f32) -> Self {
        self.friction = mu.max(0.0);
        self
    }

    /// Starts the solver from last step's impulses of the same contact ("warm starting"): a
    /// resting stack then needs only a correction instead of rebuilding its support from zero
    /// every step, which a few Gauss–Seidel sweeps cannot do for tall stacks or heavy loads.
    #[must_use]
    pub fn with_warm_start(mut self, normal_impulse: f32, tangent_impulse: Vec3) -> Self {
        self.normal_impulse = normal_impulse.max(0.0);
        self.tangent_impulse = tangent_impulse;
        self
    }

    /// Total normal impulse applied (after [`solve_velocities`]).
    pub fn impulse(&self) -> f32 {
        self.normal_impulse
    }

    /// Total friction impulse applied (after [`solve_velocities`]).
    pub fn tangent_impulse(&self) -> Vec3 {
        self.tangent_impulse
    }

    fn relative_velocity(&self, v: &[Vec3]) -> Vec3 {
        v[self.b] - v[self.a]
    }

    /// Restitution target from the approach speed before any impulse of this step.
    fn prepare(&mut self, v: &[Vec3], settings: &SolverSettings) {
        let approach = -self.relative_velocity(v).dot(self.normal);
        self.resting = approach <= settings.restitution_threshold;
        let e = if self.resting { 0.0 } else { self.restitution };
        self.target_speed = e * approach.max(0.0);
    }

    /// Applies the warm-start impulses, projected on this step's normal and tangent plane.
    fn warm_start(&mut self, v: &mut [Vec3], im: &[f32]) {
        let n = self.normal;
        self.tangent_impulse -= n * self.tangent_impulse.dot(n);
        self.tangent_impulse =
            clamp_length(self.tangent_impulse, self.friction * self.normal_impulse);
        self.apply(n * self.normal_impulse + self.tangent_impulse, v, im);
    }

    /// Impulse `p` on `b`, `-p` on `a`.
    fn apply(&self, p: Vec3, v: &mut [Vec3], im: &[f32]) {
        v[self.a] -= p * im[self.a];
        v[self.b] += p * im[self.b];
    }

    /// Returns the change of relative speed it made (m/s).
    fn solve_normal(&mut self, v: &mut [Vec3], im: &[f32], k: f32) -> f32 {
        let error = self.target_speed - self.relative_velocity(v).dot(self.normal);
        let total = (self.normal_impulse + error / k).max(0.0);
        let j = total - self.normal_impulse;
        self.normal_impulse = total;
        self.apply(self.normal * j, v, im);
        j.abs() * k
    }

    /// Shock propagation: a resting contact still approaching after the sweeps is stopped by
    /// changing the upper body's velocity alone (the lower one counts as fixed). Not added to
    /// the accumulated impulse, so warm starting keeps learning the physical impulses.
    fn propagate_shock(&self, v: &mut [Vec3], im: &[f32], level: &[u32]) {
        if self.target_speed > 0.0 {
            return; // a bounce: the sweeps' answer stands
        }
        let approach = -self.relative_velocity(v).dot(self.normal);
        if approach <= 0.0 {
            return;
        }
        match level[self.a].cmp(&level[self.b]) {
            std::cmp::Ordering::Less if im[self.b] > 0.0 => v[self.b] += self.normal * approach,
            std::cmp::Ordering::Greater if im[self.a] > 0.0 => v[self.a] -= self.normal * approach,
            _ => {}
        }
    }

    /// Friction: cancel the tangential relative velocity, within the Coulomb disc.
    /// Returns the change of relative speed it made (m/s).
    fn solve_friction(&mut self, v: &mut [Vec3], im: &[f32], k: f32) -> f32 {
        if self.friction <= 0.0 {
            return 0.0;
        }
        let n = self.normal;
        let rel = self.relative_velocity(v);
        let slide = rel - n * rel.dot(n);
        let wanted = self.tangent_impulse - slide / k;
        let total = clamp_length(
            wanted - n * wanted.dot(n),
            self.friction * self.normal_impulse,
        );
        let p = total - self.tangent_impulse;
        self.tangent_impulse = total;
        self.apply(p, v, im);
        p.length() * k
    }
}

fn clamp_length(v: Vec3, max: f32) -> Vec3 {
    let len = v.length();
    if len > max && len > 0.0 {
        v * (max / len)
    } else {
        v
    }
}

/// A sweep of the velocity constraints that changes no relative speed by more than this (m/s)
/// ends the iterations early.
const CONVERGED_SPEED: f32 = 1e-6;

/// Solves the velocity constraints in place; `inverse_mass[i] == 0` marks immovable bodies.
///
/// With `levels` (from [`SupportGraph`]), a final shock-propagation pass walks the contacts from
/// the ground up and removes whatever approach is left at resting contacts by moving only the
/// upper body, as if the lower one were fixed (Guendelman, Bridson & Fedkiw 2003). Where the
/// sweeps converged it changes nothing; where they could not (a heavy load on a light body) it
/// keeps the stack from sinking or ringing.
pub fn solve_velocities(
    contacts: &mut [ContactConstraint],
    velocities: &mut [Vec3],
    inverse_mass: &[f32],
    levels: Option<&[u32]>,
    settings: &SolverSettings,
) {
    for c in contacts.iter_mut() {
        c.prepare(velocities, settings);
    }
    for c in contacts.iter_mut() {
        c.warm_start(velocities, inverse_mass);
    }
    for _ in 0..settings.velocity_iterations.clamp(1, MAX_ITERATIONS) {
        let mut largest_change = 0.0f32;
        for c in contacts.iter_mut() {
            let k = inverse_mass[c.a] + inverse_mass[c.b];
            if k > 0.0 {
                let friction = c.solve_friction(velocities, inverse_mass, k);
                let normal = c.solve_normal(velocities, inverse_mass, k);
                largest_change = largest_change.max(friction).max(normal);
            }
        }
        // Converged: another sweep would change no velocity by more than rounding. Isolated
        // resting contacts (most of a settled scene) get here after a sweep or two.
        if largest_change < CONVERGED_SPEED {
            break;
        }
    }
    if let Some(level) = levels {
        for c in contacts.iter() {
            c.propagate_shock(velocities, inverse_mass, level);
        }
    }
}

/// How far the contact response moves bodies that are only in *resting* contacts, this step:
/// the motion their solved velocity would have made minus the motion the integrator made,
/// `(v_after - v_before)·dt`, but never more than the penetration of a contact it undoes.
///
/// urto detects contacts after integrating (the slides' order), so each step gravity first moves
/// a resting body `g·dt²` into its support and only then does the solver stop it. Undoing that
/// motion with the solved velocity — friction included — keeps stacks and piles from sinking
/// and creeping sideways, as solving velocities before integrating positions does in Box2D.
/// Bodies in an impact are left to [`correct_positions`]; a body arriving from above is moved
/// back only as far as it went in, so it lands on the surface instead of hovering. Pass the
/// result to [`correct_positions`] as its starting displacement.
pub fn resting_displacements(
    contacts: &[ContactConstraint],
    velocities_before: &[Vec3],
    velocities_after: &[Vec3],
    dt: f32,
    out: &mut Vec<Vec3>,
    scale: &mut Vec<f32>,
) {
    let n = velocities_before.len();
    // scale < 0 marks a body in an impact (no settling); otherwise the fraction kept.
    scale.clear();
    scale.resize(n, 1.0);
    for c in contacts.iter().filter(|c| !c.resting) {
        scale[c.a] = -1.0;
        scale[c.b] = -1.0;
    }
    out.clear();
    out.extend(
        velocities_before
            .iter()
            .zip(velocities_after)
            .map(|(b, a)| (*a - *b) * dt),
    );
    for c in contacts {
        for (body, outward) in [(c.a, -c.normal), (c.b, c.normal)] {
            let undo = out[body].dot(outward);
            if scale[body] > 0.0 && undo > c.depth {
                scale[body] = scale[body].min(c.depth.max(0.0) / undo);
            }
        }
    }
    for (d, k) in out.iter_mut().zip(scale.iter()) {
        *d *= k.max(0.0);
    }
}

/// Support levels of the contact graph (Guendelman, Bridson & Fedkiw 2003, "Nonconvex rigid
/// bodies with stacking", shock propagation): immovable bodies are level 0, a body touching a
/// level-`k` body is level `k+1`, bodies with no chain of contacts down to an immovable one are
/// unsupported (`u32::MAX`).
///
/// Ordering contacts by level makes each Gauss–Seidel sweep carry corrections from the ground up
/// a whole stack at once; and in position correction the lower body of a contact is treated as
/// fixed, so a light box under a heavy one is not pushed back into the floor.
#[derive(Debug, Default)]
pub struct SupportGraph {
    level: Vec<u32>,
    first: Vec<u32>,
    next: Vec<u32>,
    queue: Vec<u32>,
}

const NONE: u32 = u32::MAX;

impl SupportGraph {
    /// Computes the levels of `inverse_mass.len()` bodies and sorts `contacts` from the ground up
    /// (stable: contacts of equal level keep their order).
    pub fn order(&mut self, contacts: &mut [ContactConstraint], inverse_mass: &[f32]) {
        self.link(contacts, inverse_mass.len());
        self.level.clear();
        self.level.resize(inverse_mass.len(), NONE);
        self.queue.clear();
        for (i, im) in inverse_mass.iter().enumerate() {
            if *im == 0.0 {
                self.level[i] = 0;
                self.queue.push(i as u32);
            }
        }
        let mut head = 0;
        while head < self.queue.len() {
            let body = self.queue[head] as usize;
            head += 1;
            let mut edge = self.first[body];
            while edge != NONE {
                let c = &contacts[edge as usize / 2];
                let other = if edge.is_multiple_of(2) { c.b } else { c.a };
                if self.level[other] == NONE {
                    self.level[other] = self.level[body] + 1;
                    self.queue.push(other as u32);
                }
                edge = self.next[edge as usize];
            }
        }
        let level = &self.level;
        contacts.sort_by_key(|c| level[c.a].min(level[c.b]));
    }

    /// Level of each body after [`order`](Self::order).
    pub fn levels(&self) -> &[u32] {
        &self.level
    }

    /// Per-body linked lists of half-edges: edge `2i` is contact `i` seen from `a`, `2i+1` from `b`.
    fn link(&mut self, contacts: &[ContactConstraint], bodies: usize) {
        self.first.clear();
        self.first.resize(bodies, NONE);
        self.next.clear();
        self.next.resize(contacts.len() * 2, NONE);
        for (i, c) in contacts.iter().enumerate() {
            for (side, body) in [(0, c.a), (1, c.b)] {
                let edge = (2 * i + side) as u32;
                self.next[edge as usize] = self.first[body];
                self.first[body] = edge;
            }
        }
    }
}

/// Pushes bodies apart along the contact normals until penetration is below `slop`, starting
/// from the per-body `displacement` given (empty: none), which it extends and applies. With
/// `levels` (from [`SupportGraph`]) the lower body of a contact stays put and the upper one
/// moves; between bodies of equal level (or without levels) the motion is shared by inverse
/// mass. `positions` are moved in place.
pub fn correct_positions(
    contacts: &[ContactConstraint],
    positions: &mut [Vec3],
    inverse_mass: &[f32],
    levels: Option<&[u32]>,
    settings: &SolverSettings,
    displacement: &mut Vec<Vec3>,
) {
    // Accumulated displacement per body, so later sweeps see the penetration that is left. It
    // may arrive holding displacements already decided (see `resting_displacements`).
    displacement.resize(positions.len(), Vec3::ZERO);
    let scratch = displacement;
    for _ in 0..settings.position_iterations.min(MAX_ITERATIONS) {
        for c in contacts {
            let (mut wa, mut wb) = (inverse_mass[c.a], inverse_mass[c.b]);
            if let Some(level) = levels {
                match level[c.a].cmp(&level[c.b]) {
                    std::cmp::Ordering::Less if wb > 0.0 => wa = 0.0,
                    std::cmp::Ordering::Greater if wa > 0.0 => wb = 0.0,
                    _ => {}
                }
            }
            let k = wa + wb;
            if k <= 0.0 {
                continue;
            }
            let depth = c.depth - (scratch[c.b] - scratch[c.a]).dot(c.normal);
            let push = settings.correction_fraction * (depth - settings.slop).max(0.0) / k;
            scratch[c.a] -= c.normal * (push * wa);
            scratch[c.b] += c.normal * (push * wb);
        }
    }
    for (p, d) in positions.iter_mut().zip(scratch.iter()) {
        *p += *d;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solve_one(va: Vec3, ma: f32, vb: Vec3, mb: f32, e: f32) -> [Vec3; 2] {
        let mut v = [va, vb];
        let im = [1.0 / ma, 1.0 / mb];
        let mut c = [ContactConstraint::new(0, 1, Vec3::X, 0.0, e)];
        let settings = SolverSettings {
            restitution_threshold: 0.0,
            ..Default::default()
        };
        solve_velocities(&mut c, &mut v, &im, None, &settings);
        v
    }

    #[test]
    fn reflection_is_the_slides_formula_for_e_one() {
        let v = Vec3::new(1.0, 0.0, -3.0);
        assert_eq!(reflect(v, Vec3::Z, 1.0), Vec3::new(1.0, 0.0, 3.0));
        assert_eq!(reflect(v, Vec3::Z, 0.5), Vec3::new(1.0, 0.0, 1.5));
        // Leaving the surface: untouched.
        assert_eq!(reflect(-v, Vec3::Z, 1.0), -v);
    }

    #[test]
    fn impulses_conserve_momentum_and_elastic_ones_conserve_energy() {
        let (va, vb, ma, mb) = (
            Vec3::new(2.0, 0.5, 0.0),
            Vec3::new(-1.0, 0.0, 0.3),
            1.0,
            3.0,
        );
        for e in [0.0, 0.3, 1.0] {
            let [wa, wb] = solve_one(va, ma, vb, mb, e);
            assert!(((va * ma + vb * mb) - (wa * ma + wb * mb)).length() < 1e-5);
            let closing_before = (va - vb).dot(Vec3::X);
            let separating_after = (wb - wa).dot(Vec3::X);
            assert!(
                (separating_after - e * closing_before).abs() < 1e-5,
                "e = {e}"
            );
            if e == 1.0 {
                let ke =
                    |a: Vec3, b: Vec3| 0.5 * (ma * a.length_squared() + mb * b.length_squared());
                assert!((ke(va, vb) - ke(wa, wb)).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn an_immovable_body_reflects_the_other() {
        let [wa, wb] = solve_one(
            Vec3::new(3.0, 1.0, 0.0),
            2.0,
            Vec3::ZERO,
            f32::INFINITY,
            1.0,
        );
        assert_eq!(wb, Vec3::ZERO);
        assert!((wa - reflect(Vec3::new(3.0, 1.0, 0.0), -Vec3::X, 1.0)).length() < 1e-6);
    }

    #[test]
    fn slow_approach_does_not_bounce_and_position_correction_respects_slop() {
        let settings = SolverSettings::default();
        let mut v = [Vec3::new(0.0, 0.0, -0.1), Vec3::ZERO];
        let im = [1.0, 0.0];
        let mut c = [ContactConstraint::new(0, 1, -Vec3::Z, 0.05, 1.0)];
        solve_velocities(&mut c, &mut v, &im, None, &settings);
        assert!(v[0].z.abs() < 1e-6, "resting contact bounced: {}", v[0]);
        let mut p = [Vec3::ZERO, Vec3::ZERO];
        correct_positions(&c, &mut p, &im, None, &settings, &mut Vec::new());
        let left = 0.05 - p[0].z;
        assert!(
            left > settings.slop - 1e-6 && left < settings.slop + 0.01,
            "{left}"
        );
    }

    #[test]
    fn friction_stops_slow_sliding_and_is_capped_by_coulomb() {
        let settings = SolverSettings::default();
        let im = [1.0, 0.0];
        // A block pressed on the ground (approaching at 1 m/s) while sliding.
        let press = |slide: f32, mu: f32| {
            let mut v = [Vec3::new(slide, 0.0, -1.0), Vec3::ZERO];
            let mut c = [ContactConstraint::new(0, 1, -Vec3::Z, 0.0, 0.0).with_friction(mu)];
            solve_velocities(&mut c, &mut v, &im, None, &settings);
            (v[0], c[0])
        };
        let (v, c) = press(0.3, 0.5);
        assert!(v.length() < 1e-5, "static friction holds: {v}");
        assert!(c.tangent_impulse().length() <= 0.5 * c.impulse() + 1e-6);
        // Sliding too fast for the disc: it slows by exactly mu × normal impulse.
        let (v, c) = press(3.0, 0.5);
        assert!((v.x - (3.0 - 0.5 * c.impulse())).abs() < 1e-5, "{v}");
        assert!(v.z.abs() < 1e-5);
    }

    #[test]
    fn warm_starting_converges_a_heavy_stack_where_cold_starts_cannot() {
        // Ground (0), light box (1, 1 kg) under a heavy box (2, 100 kg); one step of gravity.
        let im = [0.0, 1.0, 0.01];
        let settings = SolverSettings::default();
        let contacts = || {
            [
                ContactConstraint::new(0, 1, Vec3::Z, 0.0, 0.0),
                ContactConstraint::new(1, 2, Vec3::Z, 0.0, 0.0),
            ]
        };
        let gravity_step = [
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, -0.1635),
            Vec3::new(0.0, 0.0, -0.1635),
        ];
        let mut cold = gravity_step;
        solve_velocities(&mut contacts(), &mut cold, &im, None, &settings);
        let mut warm_contacts = contacts();
        let mut warm = gravity_step;
        // At 100:1 each sweep removes about 1/101 of the error: warm starting keeps that progress
        // from step to step (8 sweeps each), a cold start throws it away every step.
        for _ in 0..120 {
            warm = gravity_step;
            solve_velocities(&mut warm_contacts, &mut warm, &im, None, &settings);
            for c in &mut warm_contacts {
                *c = c.with_warm_start(c.impulse(), c.tangent_impulse());
            }
        }
        assert!(
            cold[2].z < -0.05,
            "cold start leaves the heavy box falling: {}",
            cold[2]
        );
        assert!(
            warm[2].length() < 1e-4 && warm[1].length() < 1e-4,
            "{warm:?}"
        );
    }
}
