//! When a body counts as still, for sleeping: it has stayed within `speed × time` of where its
//! current window began (its centre, and its surface as it turned: the angle times its reach),
//! so its net displacement over the window is below the sleep speed's. This is Jolt's sleep test
//! (`Body::UpdateSleepStateInternal`: three points of the body must stay within a sphere of
//! `mPointVelocitySleepThreshold × mTimeBeforeSleep`), and close to rapier's (the pose's drift
//! over each step, at twice the speed threshold); Box2D v3 compares the instantaneous speed.
//!
//! Why the displacement and not the speed: a pile held by stiff soft contacts keeps a small
//! oscillation that decays slowly. urto's 210-box pyramid breathed by about ±7 mm at 3 Hz, its
//! boxes passing 0.1 m/s, for more than two seconds while going nowhere; by the speed it slept
//! at step 158–170, by the displacement it sleeps as soon as it has settled. A body drifting
//! steadily at speed `u` still sleeps only when `u` is below the sleep speed, as before. What
//! changes is a body accelerating from rest (a ball set on a gentle slope): it is still while
//! it has covered less than `speed × time` in the window, so it now sleeps below about twice
//! the acceleration it did: a ball set on a ramp from rest (its surface, at `r√3` of its
//! centre, counts) now stays asleep below about 0.94° where it did below 0.47°, and, worse, a
//! body that stops and turns back sits for a moment near its turning point: a ball rolled up a
//! ramp of about 2.8° (0.9° before) or a pendulum swinging by about 3–5° (1.2° before) can
//! freeze there, tilted (a read-only review's model at 60 Hz). Jolt's rule, with no speed
//! cap, freezes them more readily; rapier's drift rule (0.1 m/s per step) sits between. A body
//! that must not freeze so carries `SleepingDisabled`.
//!
//! The window slides: once a body has been still for a whole sleep time its window starts
//! again where it is, its still time kept, so a body creeping at a few millimetres a second (a
//! pile's slow settling) stays still however long it creeps. Without that, a 1,000-body pile
//! whose bodies each crept 2.5 cm in 5–8 s never slept: one island, and at every moment some
//! body's window had just run out.
//!
//! A body faster than four times the sleep speed (0.2 m/s with the defaults, the speed of a
//! 2 mm hop) is never still, whatever its window: a ball's last small bounces, which stay
//! within the window, must not freeze it in the air (Jolt's pure displacement test would).

use glam::{Quat, Vec3};

/// A body's pose: its centre and orientation.
pub type Pose = (Vec3, Quat);

/// The still test of a sleep speed and time (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StillTest {
    /// The farthest a still body may have gone from where its window began (m).
    pub limit: f32,
    /// The fastest a still body's centre or surface may move now (m/s).
    pub fastest: f32,
    /// How long a window lasts before it starts again where the body is (s): the sleep time.
    pub window: f32,
}

impl StillTest {
    /// The test of a body still below `speed` on average over `time`. A NaN or negative speed
    /// or time, or a zero speed, makes a test that finds no body still (a zero time, one that
    /// finds only a body exactly at rest still); the ECS refuses them before they get here
    /// (`SleepSettings`).
    pub fn new(speed: f32, time: f32) -> Self {
        Self {
            limit: speed * time,
            fastest: 4.0 * speed,
            window: time,
        }
    }

    /// One more step of `dt`: how long the body has been still after it (0: not still), and
    /// whether its window starts again at `now` (it moved, or the window is a sleep time old),
    /// given where its window began and its pose now (`start`, `now`), how fast its centre or
    /// surface moves now (`speed`: the larger of `|v|` and `|ω|` × reach) and its `reach` (how
    /// far its surface is from its centre). A NaN anywhere is not still.
    pub fn step(
        &self,
        still_for: f32,
        (start, now): (Pose, Pose),
        speed: f32,
        reach: f32,
        dt: f32,
    ) -> (f32, bool) {
        let moved = start.0.distance(now.0);
        let turned = turn_angle(start.1, now.1) * reach;
        let near = moved.max(turned) <= self.limit && !moved.is_nan() && !turned.is_nan();
        if !(near && speed < self.fastest) {
            return (0.0, true);
        }
        let after = still_for + dt;
        let windows = |t: f32| (t / self.window).floor();
        (after, windows(after) > windows(still_for))
    }
}

/// The angle between two orientations, from the vector part of the turn between them: exact
/// near zero, where `Quat::angle_between` (an `acos` of the dot product) reads about 8e-4 rad
/// for two equal unit quaternions whose dot rounds below 1 (2 cm at a 30 m reach).
fn turn_angle(a: Quat, b: Quat) -> f32 {
    let d = a.conjugate() * b;
    2.0 * d.xyz().length().atan2(d.w.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f32 = 1.0 / 60.0;

    /// The defaults: 0.05 m/s for 0.5 s.
    fn test() -> StillTest {
        StillTest::new(0.05, 0.5)
    }

    /// Steps a body along `path` (seconds → pose), its speed by finite differences, restarting
    /// its window as the sleep plugin does; returns the longest still time reached within
    /// `seconds`.
    fn longest_still(path: impl Fn(f32) -> Pose, reach: f32, seconds: f32) -> f32 {
        let (mut still, mut start, mut best) = (0.0f32, path(0.0), 0.0f32);
        for i in 1..=(seconds / DT) as u32 {
            let (before, now) = (path((i - 1) as f32 * DT), path(i as f32 * DT));
            let turn = now.1.angle_between(before.1) * reach;
            let speed = now.0.distance(before.0).max(turn) / DT;
            let restart;
            (still, restart) = test().step(still, (start, now), speed, reach, DT);
            if restart {
                start = now;
            }
            best = best.max(still);
        }
        best
    }

    #[test]
    fn a_body_breathing_7_mm_at_3_hz_is_still_though_it_passes_0_13_m_per_s() {
        let path = |t: f32| {
            let y = 0.007 * (std::f32::consts::TAU * 3.0 * t).sin();
            (Vec3::new(0.0, y, 1.0), Quat::IDENTITY)
        };
        assert!(longest_still(path, 0.9, 2.0) > 1.9);
    }

    #[test]
    fn a_steady_drift_is_still_below_the_sleep_speed_and_never_above_it_by_10_percent() {
        let drift = |u: f32| move |t: f32| (Vec3::new(u * t, 0.0, 0.0), Quat::IDENTITY);
        assert!(longest_still(drift(0.045), 0.5, 3.0) >= 0.5);
        assert!(longest_still(drift(0.055), 0.5, 3.0) < 0.5);
    }

    #[test]
    fn a_body_turning_its_surface_faster_than_the_sleep_speed_is_never_still_for_the_sleep_time() {
        // 0.2 rad/s at a 1 m reach: its surface moves at 0.2 m/s, its centre not at all.
        let spin = |t: f32| (Vec3::ZERO, Quat::from_rotation_z(0.2 * t));
        assert!(longest_still(spin, 1.0, 3.0) < 0.5);
        // 0.06 rad/s, under the speed cap but 6 cm/s at the surface on average: not still.
        let slow = |t: f32| (Vec3::ZERO, Quat::from_rotation_z(0.06 * t));
        assert!(longest_still(slow, 1.0, 3.0) < 0.5);
        // Rocking by ±0.01 rad at the same reach: still.
        let rock = |t: f32| (Vec3::ZERO, Quat::from_rotation_z(0.01 * (10.0 * t).sin()));
        assert!(longest_still(rock, 1.0, 2.0) > 1.9);
    }

    #[test]
    fn accelerating_from_rest_at_0_25_m_per_s2_is_never_still_and_at_0_15_is() {
        let ramp = |a: f32| move |t: f32| (Vec3::new(0.5 * a * t * t, 0.0, 0.0), Quat::IDENTITY);
        assert!(longest_still(ramp(0.25), 0.5, 3.0) < 0.5);
        assert!(longest_still(ramp(0.15), 0.5, 0.6) >= 0.5);
    }

    #[test]
    fn a_body_creeping_4_8_cm_in_12_s_stays_still_for_the_12_s() {
        // 4 mm/s, a tenth of the sleep speed, for 12 s: 4.8 cm in all, more than one window's
        // 2.5 cm: still only because the windows slide.
        let creep = |t: f32| (Vec3::new(0.004 * t, 0.0, 0.0), Quat::IDENTITY);
        assert!(longest_still(creep, 0.5, 12.0) > 11.9);
        let turn = |t: f32| (Vec3::ZERO, Quat::from_rotation_z(0.008 * t));
        assert!(longest_still(turn, 0.5, 12.0) > 11.9);
    }

    #[test]
    fn a_ball_hopping_1_cm_is_never_still_and_one_hopping_under_1_mm_is() {
        // Bounces of height h under gravity, over and over: the window holds them, the speed
        // (√(2 g h): 0.44 m/s at 1 cm) does not.
        let hops = |h: f32| {
            move |t: f32| {
                let period = 2.0 * (2.0 * h / 9.81).sqrt();
                let s = t % period - 0.5 * period;
                let z = h - 0.5 * 9.81 * s * s;
                (Vec3::new(0.0, 0.0, z), Quat::IDENTITY)
            }
        };
        assert!(longest_still(hops(0.01), 0.5, 3.0) < 0.5);
        assert!(longest_still(hops(0.0008), 0.5, 1.0) >= 0.5);
    }

    #[test]
    fn a_body_turned_by_nothing_reads_no_turn_within_1e_6_rad() {
        // Unit quaternions whose dot with themselves rounds below 1.
        let mut worst = 0.0f32;
        for i in 0..1000 {
            let q = Quat::from_euler(glam::EulerRot::XYZ, i as f32 * 0.37, i as f32 * 0.11, 0.3)
                .normalize();
            worst = worst.max(turn_angle(q, q));
        }
        assert!(worst < 1e-6, "{worst}");
        let q = Quat::from_rotation_z(0.25);
        assert!((turn_angle(Quat::IDENTITY, q) - 0.25).abs() < 1e-6);
        assert!((turn_angle(q, -q)).abs() < 1e-6); // the same orientation
    }

    #[test]
    fn a_test_of_a_nan_negative_or_zero_speed_or_time_finds_a_body_at_rest_never_still() {
        let rest = (Vec3::ZERO, Quat::IDENTITY);
        for (speed, time) in [
            (f32::NAN, 0.5),
            (0.05, f32::NAN),
            (-0.05, 0.5),
            (0.05, -0.5),
            (0.0, 0.5),
            (f32::NEG_INFINITY, 0.5),
        ] {
            let t = StillTest::new(speed, time);
            let mut still = 0.0;
            for _ in 0..120 {
                (still, _) = t.step(still, (rest, rest), 0.0, 1.0, DT);
            }
            assert_eq!(still, 0.0, "{speed} m/s, {time} s");
        }
    }

    #[test]
    fn a_nan_pose_or_speed_is_never_still() {
        let nan = (Vec3::NAN, Quat::IDENTITY);
        let here = (Vec3::ZERO, Quat::IDENTITY);
        let t = test();
        assert_eq!(t.step(1.0, (here, nan), 0.0, 1.0, DT), (0.0, true));
        assert_eq!(t.step(1.0, (here, here), 0.0, f32::NAN, DT), (0.0, true));
        assert_eq!(t.step(1.0, (here, here), f32::NAN, 1.0, DT), (0.0, true));
    }
}
