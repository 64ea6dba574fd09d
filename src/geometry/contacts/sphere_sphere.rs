//! Sphere–sphere: the slides' closed-form test `|c2-c1|² <= (r1+r2)²`.

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
}
