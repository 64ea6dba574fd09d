//! Separating-axis tests between two boxes, shared by [`Aabb`](super::Aabb) and
//! [`Obb`](super::Obb) (Gottschalk, Lin and Manocha 1996, "OBBTree", §5).
//!
//! Both tests run in the frame of box A, whose axes are the coordinate axes there. Box B is given
//! by its centre offset `t` (B's centre minus A's, in that frame), its axes as the columns of `r`,
//! and `abs_r = |r| + ε` (see [`ABS_ROTATION_EPSILON`](super::ABS_ROTATION_EPSILON)).
//!
//! - [`face_axes`]: the 6 face normals only (van den Bergen 1997's "SAT lite"): cheaper, and
//!   conservative, since an omitted axis can only miss a separation, never invent one.
//! - [`all_axes`]: the full 15 axes (3 + 3 face normals, 9 edge cross products): exact for boxes.
//!
//! With `ESTIMATE` set they also return the overlap ratio of [`super::Bv::overlap_estimate`]
//! (the smallest over the examined axes); without it the ratio is never computed.

use super::overlap_ratio;
use glam::{Mat3A, Vec3A};

/// One axis: `None` when the projected intervals are apart, else the running minimum ratio.
#[inline(always)]
fn axis<const ESTIMATE: bool>(best: f32, distance: f32, ra: f32, rb: f32) -> Option<f32> {
    if distance.abs() > ra + rb {
        None
    } else if ESTIMATE {
        Some(best.min(overlap_ratio(ra, rb, distance)))
    } else {
        Some(best)
    }
}

/// The 6 face-normal axes. `slack` widens every interval (rounding tolerance).
#[inline(always)]
pub(crate) fn face_axes<const ESTIMATE: bool>(
    ha: Vec3A,
    hb: Vec3A,
    t: Vec3A,
    r: &Mat3A,
    abs_r: &Mat3A,
    slack: f32,
) -> Option<f32> {
    let ha = ha + Vec3A::splat(slack);
    // A's axes: B's radius along A_i is row i of |R| times hb.
    let rb_on_a = *abs_r * hb;
    // B's axes: the offset and A's radius seen along B_j.
    let t_on_b = r.transpose() * t;
    let ra_on_b = abs_r.transpose() * ha;
    if !ESTIMATE {
        let apart_on_a = t.abs().cmpgt(ha + rb_on_a).any();
        let apart_on_b = t_on_b.abs().cmpgt(ra_on_b + hb).any();
        return (!(apart_on_a || apart_on_b)).then_some(1.0);
    }
    let mut best = 1.0;
    for i in 0..3 {
        best = axis::<true>(best, t[i], ha[i], rb_on_a[i])?;
        best = axis::<true>(best, t_on_b[i], ra_on_b[i], hb[i])?;
    }
    Some(best)
}

/// The 15 axes of the box–box separating-axis theorem.
#[inline(always)]
pub(crate) fn all_axes<const ESTIMATE: bool>(
    ha: Vec3A,
    hb: Vec3A,
    t: Vec3A,
    r: &Mat3A,
    abs_r: &Mat3A,
    slack: f32,
) -> Option<f32> {
    let mut best = face_axes::<ESTIMATE>(ha, hb, t, r, abs_r, slack)?;
    let ha = ha + Vec3A::splat(slack);
    // rc[j][i] = A_i · B_j (column-major, as glam stores it).
    let rc = r.to_cols_array_2d();
    let ac = abs_r.to_cols_array_2d();
    for i in 0..3 {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        for j in 0..3 {
            let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
            // Axis A_i × B_j.
            let ra = ha[i1] * ac[j][i2] + ha[i2] * ac[j][i1];
            let rb = hb[j1] * ac[j2][i] + hb[j2] * ac[j1][i];
            let distance = t[i2] * rc[j][i1] - t[i1] * rc[j][i2];
            best = axis::<ESTIMATE>(best, distance, ra, rb)?;
        }
    }
    Some(best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn abs_eps(r: &Mat3A) -> Mat3A {
        let e = Vec3A::splat(super::super::ABS_ROTATION_EPSILON);
        Mat3A::from_cols(r.x_axis.abs() + e, r.y_axis.abs() + e, r.z_axis.abs() + e)
    }

    /// Two long thin boxes crossing like an X but offset along z are separated only by an edge
    /// axis: the 6 face axes must say "overlap" (conservative), the 15 axes "apart".
    #[test]
    fn edge_axis_separates_what_face_axes_cannot() {
        let ha = Vec3A::new(5.0, 0.05, 0.05);
        let hb = Vec3A::new(5.0, 0.05, 0.05);
        let r = Mat3A::from_quat(Quat::from_euler(glam::EulerRot::XYZ, 0.5, 0.6, 0.7));
        // Shift B along A_x × B_x, the common normal of the two long edges.
        let n = Vec3A::X.cross(r.x_axis).normalize();
        let t = n * 0.3;
        let abs_r = abs_eps(&r);
        assert!(face_axes::<false>(ha, hb, t, &r, &abs_r, 0.0).is_some());
        assert!(all_axes::<false>(ha, hb, t, &r, &abs_r, 0.0).is_none());
    }

    #[test]
    fn estimate_and_bool_paths_agree() {
        let ha = Vec3A::new(1.0, 2.0, 0.5);
        let hb = Vec3A::new(0.7, 0.3, 1.5);
        let r = Mat3A::from_quat(Quat::from_euler(glam::EulerRot::XYZ, 0.4, -1.2, 2.2));
        let abs_r = abs_eps(&r);
        for k in 0..200 {
            let s = k as f32 * 0.03;
            let t = Vec3A::new(s.sin() * s, (1.7 * s).cos() * s, 0.3 * s);
            let b = all_axes::<false>(ha, hb, t, &r, &abs_r, 0.0).is_some();
            let e = all_axes::<true>(ha, hb, t, &r, &abs_r, 0.0);
            assert_eq!(b, e.is_some());
            assert!(e.is_none_or(|x| (0.0..=1.0).contains(&x)));
        }
    }
}
