//! Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations (Jacobi 1846; see
//! Golub and Van Loan, "Matrix Computations", §8.5), for the OBB's principal axes.
//!
//! Jacobi is slower than a closed-form cubic but unconditionally stable: its eigenvectors stay
//! orthonormal even for repeated or zero eigenvalues (flat, collinear or coincident point sets),
//! which is exactly where the closed form breaks down. Runs in f64; a 3×3 converges in a handful
//! of sweeps.

use glam::{DMat3, DVec3};

/// Sweeps after which we stop even if not fully converged (never reached in practice: Jacobi
/// converges quadratically, 3×3 matrices take about 5 sweeps in f64).
const MAX_SWEEPS: usize = 32;

/// Eigenvalues and the matching eigenvectors (columns of `vectors`, orthonormal).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SymmetricEigen {
    /// Eigenvalues, in no particular order.
    pub values: DVec3,
    /// Column `i` is the unit eigenvector of `values[i]`.
    pub vectors: DMat3,
}

/// Decomposes the symmetric matrix `m` (only its symmetric part is used) to f64 precision.
pub(crate) fn symmetric_eigen(m: DMat3) -> SymmetricEigen {
    symmetric_eigen_within(m, 1e-30)
}

/// Decomposes `m` until every off-diagonal entry is small next to *its own* two diagonal
/// entries: `a_pq² <= tolerance · |a_pp a_qq|` (or at f64's noise, `1e-30` of the diagonal's
/// squares). With `1e-12`, `a_pq` is a millionth of the geometric mean of `a_pp` and `a_qq`,
/// so the eigenvectors of two eigenvalues are within `1e-6 √(a_pp a_qq) / |a_pp − a_qq|`
/// radians of exact however small both are next to the third: a thin strip's thickness axis
/// stays exact, where a tolerance relative to the whole diagonal turned it by up to 0.8 rad.
pub(crate) fn symmetric_eigen_within(m: DMat3, tolerance: f64) -> SymmetricEigen {
    // a[c][r]: column-major, symmetric so the layout does not matter for reads of a[p][q].
    let mut a = ((m + m.transpose()) * 0.5).to_cols_array_2d();
    let mut v = DMat3::IDENTITY.to_cols_array_2d();
    for _ in 0..MAX_SWEEPS {
        let diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        let converged = [(0, 1), (0, 2), (1, 2)].iter().all(|&(p, q)| {
            let off = a[p][q] * a[p][q];
            off <= tolerance * (a[p][p] * a[q][q]).abs() || off <= 1e-30 * diag
        });
        if converged {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            rotate(&mut a, &mut v, p, q);
        }
    }
    SymmetricEigen {
        values: DVec3::new(a[0][0], a[1][1], a[2][2]),
        vectors: DMat3::from_cols_array_2d(&v),
    }
}

/// One Jacobi rotation zeroing `a[p][q]`: `a ← Jᵀ a J`, `v ← v J`.
fn rotate(a: &mut [[f64; 3]; 3], v: &mut [[f64; 3]; 3], p: usize, q: usize) {
    let apq = a[p][q];
    if apq == 0.0 {
        return;
    }
    let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
    // The smaller root of t² + 2θt − 1 = 0, written to avoid overflow for huge θ.
    let t = if theta.abs() > 1e150 {
        0.5 / theta
    } else {
        theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
    };
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    // Columns p and q of a (a ← a J)…
    let (cp, cq) = (a[p], a[q]);
    a[p] = std::array::from_fn(|k| c * cp[k] - s * cq[k]);
    a[q] = std::array::from_fn(|k| s * cp[k] + c * cq[k]);
    // …then rows p and q (a ← Jᵀ a), entry p and q of every column.
    for col in a.iter_mut() {
        let (x, y) = (col[p], col[q]);
        col[p] = c * x - s * y;
        col[q] = s * x + c * y;
    }
    let (vp, vq) = (v[p], v[q]);
    v[p] = std::array::from_fn(|k| c * vp[k] - s * vq[k]);
    v[q] = std::array::from_fn(|k| s * vp[k] + c * vq[k]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(m: DMat3) {
        let e = symmetric_eigen(m);
        let vt_v = e.vectors.transpose() * e.vectors;
        assert!(
            (vt_v - DMat3::IDENTITY)
                .abs()
                .to_cols_array()
                .iter()
                .all(|x| *x < 1e-12)
        );
        for i in 0..3 {
            let x = e.vectors.col(i);
            let residual = m * x - x * e.values[i];
            assert!(
                residual.length() < 1e-10 * (1.0 + m.abs().to_cols_array().iter().sum::<f64>())
            );
        }
    }

    /// A thin flat strip (variances 1, 1e-6, 0 along turned axes): to the box tolerance,
    /// the thickness axis is found within 1e-5 rad (a tolerance relative to the whole diagonal
    /// let it turn by up to 0.8 rad).
    #[test]
    fn a_thin_strips_thickness_axis_is_found_within_1e_5_rad_at_the_box_tolerance() {
        for k in 0..200 {
            let t = k as f64 * 0.37;
            let axes = glam::DQuat::from_euler(glam::EulerRot::XYZ, t, 1.3 * t + 0.2, 0.7 * t);
            let r = DMat3::from_quat(axes);
            let m = r * DMat3::from_diagonal(DVec3::new(1.0, 1e-6, 0.0)) * r.transpose();
            let e = symmetric_eigen_within(m, 1e-12);
            let thin = (0..3)
                .min_by(|&i, &j| e.values[i].abs().total_cmp(&e.values[j].abs()))
                .unwrap_or(0);
            let error = e.vectors.col(thin).dot(r.z_axis).abs().min(1.0).acos();
            assert!(error < 1e-5, "turn {t}: {error} rad");
        }
    }

    #[test]
    fn decomposes_general_repeated_and_zero_matrices() {
        check(DMat3::from_cols(
            DVec3::new(4.0, 1.0, -2.0),
            DVec3::new(1.0, 3.0, 0.5),
            DVec3::new(-2.0, 0.5, 7.0),
        ));
        check(DMat3::from_diagonal(DVec3::new(2.0, 2.0, 2.0)));
        check(DMat3::ZERO);
        // Rank one: the covariance of collinear points.
        let d = DVec3::new(1.0, -2.0, 0.5);
        check(DMat3::from_cols(d * d.x, d * d.y, d * d.z));
        // Huge spread of magnitudes.
        check(DMat3::from_cols(
            DVec3::new(1e12, 1e-3, 0.0),
            DVec3::new(1e-3, 1e-12, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ));
    }
}
