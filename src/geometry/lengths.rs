//! Lengths taken from arithmetic that can overflow or from public inputs: a margin, a motion
//! bound, a lever arm, a rounding radius. Each is used as a distance, where a NaN or a negative
//! value would spread or invert what it bounds; such a value counts as no length at all.

/// `x` when it is a finite length (`>= 0`), a negative finite `x` clamped to 0, and 0 for NaN
/// or an infinity.
#[inline]
pub fn length_or_zero(x: f32) -> f32 {
    if x.is_finite() { x.max(0.0) } else { 0.0 }
}

/// Whether `q` is a rotation the engine can use: finite, and a unit quaternion within 1e-3 (a
/// body's rotation, a joint's frame, a kinematic target's).
#[inline]
pub fn is_unit_rotation(q: glam::Quat) -> bool {
    q.is_finite() && (q.length() - 1.0).abs() < 1e-3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_length_is_kept_and_anything_else_is_zero() {
        assert_eq!(length_or_zero(2.5), 2.5);
        assert_eq!(length_or_zero(0.0), 0.0);
        for bad in [-1.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(length_or_zero(bad), 0.0, "{bad}");
        }
    }
}
