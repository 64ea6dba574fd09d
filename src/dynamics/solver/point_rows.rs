//! The point rows of a joint: the three rows keeping two anchors together (a ball joint's
//! whole constraint, and the anchor part of a hinge, a weld or a slider), with the notation of
//! [`joint_rows`](super::joint_rows) (Avian's `PointConstraintPart`, Jolt's
//! `PointConstraintPart`).
//!
//! With `C = c_b + r_b − c_a − r_a`, `Ċ = v_b + ω_b × r_b − v_a − ω_a × r_a`; as
//! `ω × r = −[r]× ω`, `J = [−1, [r_a]×, 1, −[r_b]×]` and
//! `K = (m_a⁻¹ + m_b⁻¹) 1 − [r_a]× I_a⁻¹ [r_a]× − [r_b]× I_b⁻¹ [r_b]×` (3×3, symmetric). The
//! batched ball joints take the same `K` four at a time in lanes
//! ([`Mat3x4::skew_sandwich`](super::lanes::Mat3x4::skew_sandwich)).

use super::body::BodyState;
use super::joint_rows::PairMasses;
use super::softness::Softness;
use glam::{Mat3, Vec3};

/// `[v]×`, the matrix of `x ↦ v × x`.
pub fn skew(v: Vec3) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, v.z, -v.y),
        Vec3::new(-v.z, 0.0, v.x),
        Vec3::new(v.y, -v.x, 0.0),
    )
}

/// The point rows' `K` for anchors `r_a`, `r_b` (see the module doc).
#[inline]
pub fn point_mass(m: &PairMasses, r_a: Vec3, r_b: Vec3) -> Mat3 {
    let [ia, ib] = m.inverse_inertia;
    Mat3::from_diagonal(m.inverse_mass[0] + m.inverse_mass[1])
        - skew_sandwich(r_a, ia)
        - skew_sandwich(r_b, ib)
}

/// `[r]× I [r]×` in 36 multiplications instead of two matrix products' 54 (it is taken for
/// every joint in every substep): the columns of `[r]× I` are `r` crossed with `I`'s columns,
/// and multiplying by `[r]×` combines them with `[r]×`'s entries, a third of which are zero.
#[inline]
fn skew_sandwich(r: Vec3, i: Mat3) -> Mat3 {
    let c = [r.cross(i.x_axis), r.cross(i.y_axis), r.cross(i.z_axis)];
    Mat3::from_cols(
        c[1] * r.z - c[2] * r.y,
        c[2] * r.x - c[0] * r.z,
        c[0] * r.y - c[1] * r.x,
    )
}

/// Solves the point rows: anchors `r_a`, `r_b` (world, now), position error `c` (`None` in a
/// relax pass), `k_inverse` the rows' effective mass ([`point_mass`] inverted by
/// [`inverse_mass`]); `accumulated` is the world impulse on B. Returns the impulse applied.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn solve_point(
    m: &PairMasses,
    states: &mut [BodyState],
    (a, b): (usize, usize),
    (r_a, r_b): (Vec3, Vec3),
    error: Option<Vec3>,
    soft: Softness,
    k_inverse: &Mat3,
    accumulated: &mut Vec3,
) -> Vec3 {
    let (sa, sb) = (&states[a], &states[b]);
    let cdot = sb.linear_velocity + sb.angular_velocity.cross(r_b)
        - sa.linear_velocity
        - sa.angular_velocity.cross(r_a);
    let (bias, soft) = match error {
        Some(c) => (c * soft.bias_rate, soft),
        None => (Vec3::ZERO, Softness::RIGID),
    };
    let impulse =
        -soft.mass_scale * (*k_inverse * (cdot + bias)) - soft.impulse_scale * *accumulated;
    *accumulated += impulse;
    m.apply(
        states,
        (a, b),
        impulse,
        [r_a.cross(impulse), r_b.cross(impulse)],
    );
    impulse
}

/// `K⁻¹` for a symmetric positive semi-definite `K`: the inverse when it is well
/// conditioned, else row by row (a body turning about some axes only, or two immovable
/// bodies: those rows take no impulse). Always inlined: a `K` handed over through memory
/// to a call was read back in wider loads than it was stored in, and the reads waited for the
/// stores (no store-to-load forwarding; a tenth of a ragdoll pile's point-mass work).
#[inline(always)]
pub fn inverse_mass(k: Mat3) -> Mat3 {
    let det = k.determinant();
    let scale = k.x_axis.x * k.y_axis.y * k.z_axis.z;
    if det.is_finite() && det > 1e-6 * scale && scale > 0.0 {
        return k.inverse();
    }
    let inv = |d: f32| if d > 0.0 { 1.0 / d } else { 0.0 };
    Mat3::from_diagonal(Vec3::new(inv(k.x_axis.x), inv(k.y_axis.y), inv(k.z_axis.z)))
}

#[cfg(test)]
mod tests {
    use super::super::joint_rows::tests::masses;
    use super::*;

    #[test]
    fn the_point_rows_stop_the_anchors_relative_velocity_within_1e_5() {
        let m = masses(2.0, 3.0);
        let mut states = [BodyState::default(); 2];
        states[0].linear_velocity = Vec3::new(1.0, -2.0, 0.5);
        states[0].angular_velocity = Vec3::new(0.3, 1.0, -2.0);
        states[1].angular_velocity = Vec3::new(-1.0, 0.2, 0.7);
        let (ra, rb) = (Vec3::new(0.5, 0.2, -0.1), Vec3::new(-0.3, 0.4, 0.6));
        let mut acc = Vec3::ZERO;
        let k_inverse = inverse_mass(point_mass(&m, ra, rb));
        solve_point(
            &m,
            &mut states,
            (0, 1),
            (ra, rb),
            None,
            Softness::RIGID,
            &k_inverse,
            &mut acc,
        );
        let (sa, sb) = (states[0], states[1]);
        let rel = sb.linear_velocity + sb.angular_velocity.cross(rb)
            - sa.linear_velocity
            - sa.angular_velocity.cross(ra);
        assert!(rel.length() < 1e-5, "{rel}");
    }

    #[test]
    fn the_skew_sandwich_equals_the_two_matrix_products_within_1e_5() {
        let mut rng = crate::test_rng::TestRng::new(7);
        for _ in 0..1000 {
            let r = rng.vec3(-2.0, 2.0);
            let i = Mat3::from_cols_array(&std::array::from_fn(|_| rng.range(-2.0, 2.0)));
            let expected = skew(r) * i * skew(r);
            let got = skew_sandwich(r, i);
            let scale = 1.0
                + expected
                    .abs()
                    .to_cols_array()
                    .iter()
                    .fold(0.0f32, |a, &b| a.max(b));
            assert!(
                got.abs_diff_eq(expected, 1e-5 * scale),
                "{got} vs {expected}"
            );
        }
    }

    #[test]
    fn a_singular_mass_takes_no_impulse_on_its_empty_rows() {
        let k = Mat3::from_diagonal(Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(inverse_mass(k) * Vec3::ONE, Vec3::new(0.5, 0.0, 0.0));
    }
}
