//! Sphere–sphere: the slides' closed-form test `|c2-c1|² <= (r1+r2)²`, and the speculative
//! contact of two balls closing fast, whose normal is where they will meet
//! ([`sphere_sphere_on_approach`]).

use super::FALLBACK_NORMAL;
use crate::geometry::{ContactManifold, Sphere};
use glam::Vec3;

/// Contact between a sphere centred at `ca` and one centred at `cb`.
///
/// Coincident centres give depth `ra + rb` and the normal [`FALLBACK_NORMAL`] when A is at least
/// as big as B (the smaller ball is pushed up), its opposite otherwise, so that swapping the pair
/// always flips the normal unless the two balls are identical.
pub fn contact_sphere_sphere(
    ca: Vec3,
    a: &Sphere,
    cb: Vec3,
    b: &Sphere,
) -> Option<ContactManifold> {
    let d = cb - ca;
    let reach = a.radius + b.radius;
    let dist2 = d.length_squared();
    if dist2 > reach * reach {
        return None;
    }
    let dist = dist2.sqrt();
    // Below MIN_POSITIVE the squared distance is subnormal and `d / dist` is no longer unit.
    let normal = if dist2 >= f32::MIN_POSITIVE {
        d / dist
    } else if a.radius >= b.radius {
        FALLBACK_NORMAL
    } else {
        -FALLBACK_NORMAL
    };
    let on_a = ca + normal * a.radius;
    let on_b = cb - normal * b.radius;
    Some(ContactManifold::single(
        normal,
        (on_a + on_b) * 0.5,
        (reach - dist).max(0.0),
    ))
}

/// The speculative contact of spheres `a` at `ca` and `b` at `cb`, still apart, B moving by
/// `relative` (relative to A) over the step: when that motion brings them together within it
/// or the next step, the contact's normal is their line of centres *then*, its point midway
/// between the two surfaces along it, and its depth the (negative) gap along it now; `None`
/// when the motion does not bring them together that soon (the closest points' contact
/// stands). The next step counts: the solver's last relax pass of a step already pushes a
/// contact that would close in the next substep, and so the next step's first.
///
/// Why: the solver keeps one normal for the step. Taken from the closest points at the step's
/// start, it is the line of centres while the balls are still apart, not where they meet: a
/// ball struck off-centre at 10 m/s left 7.5° off the line of centres at impact (Newton's
/// direction), 17.6° at 30 m/s, 1.3° at 1.5 m/s (equal balls of 0.5 m, impact offset 0.75 of
/// the sum of radii). For a straight relative motion `d + u t` the meeting is the smaller
/// root of `|d + u t| = r_a + r_b`, and a gap closed along that normal closes exactly there.
pub fn sphere_sphere_on_approach(
    ca: Vec3,
    a: &Sphere,
    cb: Vec3,
    b: &Sphere,
    relative: Vec3,
) -> Option<ContactManifold> {
    let d = cb - ca;
    let reach = a.radius + b.radius;
    let (uu, du) = (relative.length_squared(), d.dot(relative));
    let apart = d.length_squared() - reach * reach;
    if !(apart > 0.0 && du < 0.0 && uu > 0.0) {
        return None;
    }
    let discriminant = du * du - uu * apart;
    if discriminant.is_nan() || discriminant < 0.0 {
        return None; // they pass each other
    }
    let t = (-du - discriminant.sqrt()) / uu;
    if !(t > 0.0 && t <= 2.0) {
        return None;
    }
    let normal = (d + relative * t).normalize_or_zero();
    if normal == Vec3::ZERO {
        return None;
    }
    let on_a = ca + normal * a.radius;
    let on_b = cb - normal * b.radius;
    Some(ContactManifold::single(
        normal,
        (on_a + on_b) * 0.5,
        reach - d.dot(normal),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearly_coincident_centres_still_give_a_unit_normal() {
        let s = Sphere { radius: 0.5 };
        let m = contact_sphere_sphere(Vec3::ZERO, &s, Vec3::new(1e-22, 0.0, 0.0), &s).unwrap();
        assert!((m.normal.length() - 1.0).abs() < 1e-6, "{}", m.normal);
    }

    #[test]
    fn overlapping_touching_and_apart() {
        let s = Sphere { radius: 1.0 };
        let m = contact_sphere_sphere(Vec3::ZERO, &s, Vec3::new(1.5, 0.0, 0.0), &s).unwrap();
        assert_eq!(m.normal, Vec3::X);
        assert!((m.max_depth() - 0.5).abs() < 1e-6);
        assert!((m.points()[0].point - Vec3::new(0.75, 0.0, 0.0)).length() < 1e-6);
        let touching = contact_sphere_sphere(Vec3::ZERO, &s, Vec3::new(2.0, 0.0, 0.0), &s);
        assert_eq!(touching.unwrap().max_depth(), 0.0);
        let gap = 2.0f32.next_up();
        assert!(contact_sphere_sphere(Vec3::ZERO, &s, Vec3::new(gap, 0.0, 0.0), &s).is_none());
    }

    #[test]
    fn coincident_centres_use_the_fallback_normal() {
        let s = Sphere { radius: 0.5 };
        let m = contact_sphere_sphere(Vec3::ONE, &s, Vec3::ONE, &s).unwrap();
        assert_eq!(m.normal, FALLBACK_NORMAL);
        assert_eq!(m.max_depth(), 1.0);
        let small = Sphere { radius: 0.25 };
        let m = contact_sphere_sphere(Vec3::ONE, &small, Vec3::ONE, &s).unwrap();
        assert_eq!((m.normal, m.max_depth()), (-FALLBACK_NORMAL, 0.75));
        let points = Sphere { radius: 0.0 };
        let m = contact_sphere_sphere(Vec3::ONE, &points, Vec3::ONE, &points).unwrap();
        assert!(m.normal.is_finite() && m.max_depth() == 0.0);
    }
    #[test]
    fn an_oblique_approach_takes_the_line_of_centres_where_the_balls_meet() {
        let s = Sphere { radius: 0.5 };
        // B 0.75 to the side, 3 m ahead, closing along x by 4 m in the step: they meet where
        // B is (0.66, 0.75), the line of centres at asin(0.75) from x.
        let cb = Vec3::new(3.0, 0.75, 0.0);
        let m = sphere_sphere_on_approach(Vec3::ZERO, &s, cb, &s, Vec3::new(-4.0, 0.0, 0.0));
        let m = m.unwrap();
        let meet = Vec3::new((1.0f32 - 0.75 * 0.75).sqrt(), 0.75, 0.0);
        assert!((m.normal - meet).length() < 1e-6, "{}", m.normal);
        // The gap along that normal now: B moves 3 - 0.66 along x, whose share along n is it.
        let gap = cb.dot(meet) - 1.0;
        let depth = m.points()[0].depth;
        assert!((depth + gap).abs() < 1e-6, "{depth}");
        // Met this step or the next only if the motion reaches: not at 1 m a step, nor passing
        // aside, nor moving apart.
        let short = Vec3::new(-1.0, 0.0, 0.0);
        assert!(sphere_sphere_on_approach(Vec3::ZERO, &s, cb, &s, short).is_none());
        let aside = Vec3::new(-4.0, 1.0, 0.0);
        assert!(sphere_sphere_on_approach(Vec3::ZERO, &s, cb, &s, aside).is_none());
        let away = Vec3::new(4.0, 0.0, 0.0);
        assert!(sphere_sphere_on_approach(Vec3::ZERO, &s, cb, &s, away).is_none());
        // Touching or overlapping already: the closest points' contact stands.
        let touching = Vec3::new(1.0, 0.0, 0.0);
        assert!(sphere_sphere_on_approach(Vec3::ZERO, &s, touching, &s, -touching).is_none());
    }
}
