//! Shared helpers of the continuous-collision tests: a seeded generator of sweeps and the
//! brute-force reference (the sweep sampled finely with the existing *static* contact tests, the
//! first contact refined by bisection).

#![allow(dead_code)]

use glam::Vec3;
use urto::ccd::{SphereSweep, Toi};

/// SplitMix64 (Steele, Lea and Flood 2014): tiny, seeded, the same sequence on every machine.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in the cube `[-half, half]³`.
    pub fn in_cube(&mut self, half: f32) -> Vec3 {
        Vec3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }

    /// A uniformly random unit vector.
    pub fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.in_cube(1.0);
            if let Some(u) = v.try_normalize().filter(|_| v.length_squared() <= 1.0) {
                return u;
            }
        }
    }

    /// A radius: sometimes zero (a ray) or tiny, mostly log-uniform in `[0.01, 1]`.
    pub fn radius(&mut self) -> f32 {
        match self.next_u64() % 20 {
            0 => 0.0,
            1 => 1e-3,
            _ => 10f32.powf(self.range(-2.0, 0.0)),
        }
    }

    pub fn pick(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// A random sweep around an obstacle near the origin of size about `size`: aimed at a random
/// point near `target` half of the time, random otherwise, sometimes parallel to `plane_normal`'s
/// plane, sometimes still or barely moving.
pub fn random_sweep(
    rng: &mut Rng,
    size: f32,
    target: Vec3,
    plane_normal: Option<Vec3>,
) -> SphereSweep {
    let radius = rng.radius();
    let start = target + rng.in_cube(3.0 * size + radius);
    let mut displacement = match rng.pick(10) {
        0..=4 => {
            let aim = target + rng.in_cube(size + radius);
            (aim - start) * rng.range(0.2, 2.0)
        }
        5..=7 => rng.direction() * rng.range(0.0, 8.0 * size),
        8 => rng.direction() * rng.range(0.0, 1e-4),
        _ => Vec3::ZERO,
    };
    if let Some(n) = plane_normal.filter(|_| rng.pick(8) == 0) {
        displacement -= n * n.dot(displacement);
    }
    SphereSweep::new(start, radius, displacement).expect("finite sweep")
}

/// What the references need of an obstacle: the existing static contact test as "is a sphere of
/// this radius at this centre in contact, and with which normal (obstacle → sphere)?".
pub trait StaticOracle {
    fn contact(&self, center: Vec3, radius: f32) -> Option<Vec3>;
}

impl<F: Fn(Vec3, f32) -> Option<Vec3>> StaticOracle for F {
    fn contact(&self, center: Vec3, radius: f32) -> Option<Vec3> {
        self(center, radius)
    }
}

/// The distance slack the checks allow: rounding of the f32 queries at this scale.
pub fn position_tolerance(sweep: &SphereSweep) -> f32 {
    2e-5 * (1.0
        + sweep.radius()
        + sweep.displacement().length()
        + sweep.center().abs().max_element())
}

/// The first time the sampled sweep is in contact (refined by bisection), or `None`.
pub fn reference_first_contact(
    sweep: &SphereSweep,
    oracle: &impl StaticOracle,
    samples: usize,
) -> Option<f32> {
    let in_contact = |t: f32| {
        oracle
            .contact(sweep.position_at(t), sweep.radius())
            .is_some()
    };
    if in_contact(0.0) {
        return Some(0.0);
    }
    let first = (1..=samples)
        .map(|k| k as f32 / samples as f32)
        .find(|&t| in_contact(t))?;
    let (mut lo, mut hi) = (first - 1.0 / samples as f32, first);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if in_contact(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// What [`check_toi`] measured on one sweep.
#[derive(Default, Clone, Copy, Debug)]
pub struct Agreement {
    /// `|t − t_reference|` when both found a contact and the approach was transversal.
    pub transversal_error: Option<f32>,
    pub hit: bool,
}

/// Checks a TOI against the sampled static test:
/// - a hit at `t > 0` is a real touch (in contact at `r + ε`, not at `r − ε`) with the oracle's
///   normal, a hit at `t = 0` a real contact at the start;
/// - no sample before the hit (or anywhere, for a miss) is in contact deeper than `ε`;
/// - compared with the bisected first contact of the samples, the hit is not later (but for
///   grazes shallower than ε, which the samples may see and the query may not).
pub fn check_toi(
    sweep: &SphereSweep,
    toi: Option<Toi>,
    oracle: &impl StaticOracle,
    samples: usize,
) -> Result<Agreement, String> {
    let r = sweep.radius();
    let eps = position_tolerance(sweep);
    let deep = |t: f32| r > eps && oracle.contact(sweep.position_at(t), r - eps).is_some();
    let sample_times = (0..=samples).map(|k| k as f32 / samples as f32);
    let mut agreement = Agreement::default();
    let t_hit = match toi {
        None => {
            if let Some(t) = sample_times.clone().find(|&t| deep(t)) {
                return Err(format!("missed: deep contact at sample t = {t}"));
            }
            1.0 + 1.0 / samples as f32
        }
        Some(toi) => {
            agreement.hit = true;
            if !(0.0..=1.0).contains(&toi.t)
                || !toi.normal.is_normalized()
                || !toi.point.is_finite()
            {
                return Err(format!("malformed {toi:?}"));
            }
            let c = sweep.position_at(toi.t);
            let Some(oracle_normal) = oracle.contact(c, r + eps) else {
                return Err(format!("{toi:?} is not a contact"));
            };
            if toi.t > 0.0 && deep(toi.t) {
                return Err(format!("{toi:?} is already deep"));
            }
            if r > 0.05 && toi.t > 0.0 && oracle_normal.dot(toi.normal) < 0.999 {
                return Err(format!("normal {} vs oracle {oracle_normal}", toi.normal));
            }
            toi.t
        }
    };
    let step = 1.0 / samples as f32;
    if let Some(t) = sample_times
        .take_while(|&t| t < t_hit - step)
        .find(|&t| deep(t))
    {
        return Err(format!(
            "deep contact at sample t = {t}, before the hit at {t_hit}"
        ));
    }
    if let (Some(toi), Some(reference)) = (toi, reference_first_contact(sweep, oracle, samples)) {
        let speed = sweep.displacement().length();
        let late = toi.t - reference;
        // Later than the sampled first contact: only a graze within ε may explain it.
        if late * speed > eps
            && (0..=samples).any(|k| {
                let t = reference + (toi.t - reference) * k as f32 / samples as f32;
                deep(t)
            })
        {
            return Err(format!(
                "hit at {} but deep contact from {reference}",
                toi.t
            ));
        }
        let after = (reference + 4.0 * step).min(1.0);
        let transversal = oracle
            .contact(sweep.position_at(after), r - 10.0 * eps)
            .is_some()
            && r > 10.0 * eps
            && reference > 0.0;
        if transversal {
            agreement.transversal_error = Some((toi.t - reference).abs());
        }
    }
    Ok(agreement)
}

/// Summary over many sweeps, printed by the tests.
#[derive(Default, Debug)]
pub struct Tally {
    pub sweeps: usize,
    pub hits: usize,
    pub transversal: usize,
    pub max_transversal_error: f32,
}

impl Tally {
    pub fn add(&mut self, a: Agreement) {
        self.sweeps += 1;
        self.hits += usize::from(a.hit);
        if let Some(e) = a.transversal_error {
            self.transversal += 1;
            self.max_transversal_error = self.max_transversal_error.max(e);
        }
    }
}
