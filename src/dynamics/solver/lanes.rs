//! Four of everything: the vector, matrix and quaternion arithmetic of the batched contact and
//! joint solvers, one contact or joint per SIMD lane (rapier's `SimdReal` over `wide::f32x4`, Box2D v3's `b2FloatW`).
//!
//! Each type holds one component per lane, so `a.dot(b)` is three multiplies and two adds that
//! serve four contacts at once. The operations are written in the same order as glam's scalar
//! ones, so a lane computes what the scalar solver computes for the same contact (up to the
//! rounding of glam's quaternion rotation).

use super::body::BodyState;
use glam::{Mat3, Quat, Vec3};
use std::ops::{Add, Mul, Neg, Sub};
use wide::f32x4;

/// One float per lane.
pub type Lanes = f32x4;

/// How many contacts (or joints) a batch solves at once.
pub const LANES: usize = 4;

/// A 3-vector per lane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec3x4 {
    /// The x components, one per lane.
    pub x: Lanes,
    /// The y components, one per lane.
    pub y: Lanes,
    /// The z components, one per lane.
    pub z: Lanes,
}

impl Vec3x4 {
    /// Zero in every lane.
    pub const ZERO: Self = Self {
        x: Lanes::ZERO,
        y: Lanes::ZERO,
        z: Lanes::ZERO,
    };

    /// Lane `i` holds `v[i]` (by a 4×4 transpose, as [`Self::to_vecs`]).
    #[inline]
    pub fn gather(v: [Vec3; LANES]) -> Self {
        // Written out, not `v.map(..)`: an array map's closure may stay out of line in the
        // passes (the pyramid's solve spent 6 % of its instructions calling one).
        let lane = |v: Vec3| Lanes::new([v.x, v.y, v.z, 0.0]);
        let [x, y, z, _] = Lanes::transpose([lane(v[0]), lane(v[1]), lane(v[2]), lane(v[3])]);
        Self { x, y, z }
    }

    /// Lane `i` holds `*v[i]`, read a component at a time from where the vectors lie. A
    /// gather of copies ([`Self::gather`]) may build them on the stack first, and a 16-byte
    /// load of three 4-byte stores waits for them to land (no store-to-load forwarding): a
    /// joint net's packing spent a third of its time in such waits.
    #[inline]
    pub fn gather_refs(v: [&Vec3; LANES]) -> Self {
        Self {
            x: Lanes::new(v.map(|v| v.x)),
            y: Lanes::new(v.map(|v| v.y)),
            z: Lanes::new(v.map(|v| v.z)),
        }
    }

    /// Puts `v` in lane `i` (a row rebuilt during a step, `turned_rows.rs`).
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        set_lane(&mut self.x, i, v.x);
        set_lane(&mut self.y, i, v.y);
        set_lane(&mut self.z, i, v.z);
    }

    /// The vector of lane `i`.
    pub fn lane(&self, i: usize) -> Vec3 {
        Vec3::new(
            self.x.as_array()[i],
            self.y.as_array()[i],
            self.z.as_array()[i],
        )
    }

    /// The four vectors, by a 4×4 transpose (one shuffle network instead of twelve lane
    /// extractions: writing the batches' velocities back was a fifth of a pile's contact
    /// passes).
    #[inline]
    pub fn to_vecs(self) -> [Vec3; LANES] {
        let [a, b, c, d] = Lanes::transpose([self.x, self.y, self.z, Lanes::ZERO]);
        // Written out, not `t.map(..)`: the array map stayed out of line in the passes.
        let vec = |v: Lanes| {
            let [x, y, z, _] = v.to_array();
            Vec3::new(x, y, z)
        };
        [vec(a), vec(b), vec(c), vec(d)]
    }

    /// Per-lane dot product.
    #[inline]
    pub fn dot(self, o: Self) -> Lanes {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Per-lane cross product.
    #[inline]
    pub fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }
}

impl Add for Vec3x4 {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for Vec3x4 {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl Neg for Vec3x4 {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
}

/// Scales each lane's vector by that lane's float.
impl Mul<Lanes> for Vec3x4 {
    type Output = Self;
    fn mul(self, s: Lanes) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

/// A unit quaternion per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quatx4 {
    /// The vector part.
    pub v: Vec3x4,
    /// The scalar part.
    pub w: Lanes,
}

impl Quatx4 {
    /// The identity in every lane (the bits of `Quat::IDENTITY`).
    pub const IDENTITY: Self = Self {
        v: Vec3x4::ZERO,
        w: Lanes::ONE,
    };

    /// Lane `i` holds `q[i]`.
    #[inline]
    pub fn gather(q: [Quat; LANES]) -> Self {
        let lanes = |q: Quat| Lanes::new(q.to_array());
        let [x, y, z, w] = Lanes::transpose([lanes(q[0]), lanes(q[1]), lanes(q[2]), lanes(q[3])]);
        Self {
            v: Vec3x4 { x, y, z },
            w,
        }
    }

    /// Rotates each lane's vector: `r + 2w (u × r) + 2 u × (u × r)` for `q = (u, w)`.
    pub fn rotate(self, r: Vec3x4) -> Vec3x4 {
        let two = Lanes::splat(2.0);
        let t = self.v.cross(r) * two;
        r + t * self.w + self.v.cross(t)
    }

    /// Rotates each lane's vector by the inverse rotation (the conjugate `(−u, w)`).
    pub fn inverse_rotate(self, r: Vec3x4) -> Vec3x4 {
        Self {
            v: -self.v,
            w: self.w,
        }
        .rotate(r)
    }
}

/// Puts `x` in lane `i` of `lanes`.
pub fn set_lane(lanes: &mut Lanes, i: usize, x: f32) {
    let mut all = lanes.to_array();
    all[i] = x;
    *lanes = Lanes::new(all);
}

/// The items at `indices` one per lane (`None` past them), and the first: `None` for no
/// index, more than [`LANES`] or one out of range (what a batch's `repack` refuses).
#[allow(clippy::type_complexity)]
pub fn lanes_of<'a, T>(indices: &[u32], items: &'a [T]) -> Option<([Option<&'a T>; LANES], &'a T)> {
    if indices.is_empty() || indices.len() > LANES {
        return None;
    }
    let mut lanes: [Option<&T>; LANES] = [None; LANES];
    for (lane, &i) in lanes.iter_mut().zip(indices) {
        *lane = Some(items.get(i as usize)?);
    }
    Some((lanes, lanes[0]?))
}

/// The body slots of A and B per lane of a batch (u32, as the solver numbers its slots: half
/// the bytes of `usize` in a header every pass reads).
pub type Slots = [[u32; LANES]; 2];

/// The velocities of a batch's two bodies per lane (a contact's or a joint's A and B), gathered
/// from the solver's states and scattered back to the slots a lane may write.
#[derive(Clone, Copy, Debug)]
pub struct PairVelocities {
    /// A's linear velocities.
    pub va: Vec3x4,
    /// A's angular velocities.
    pub wa: Vec3x4,
    /// B's linear velocities.
    pub vb: Vec3x4,
    /// B's angular velocities.
    pub wb: Vec3x4,
}

impl PairVelocities {
    /// The velocities of slots `[a, b]` per lane; a `still` side (bodies at rest that nothing
    /// moves, see [`ContactConstraint::still`](super::contact::ContactConstraint::still)) is
    /// the zeros its states hold, not gathered.
    pub fn load([a, b]: &Slots, still: [bool; 2], states: &[BodyState]) -> Self {
        let side = |slots: &[u32; LANES], still: bool| {
            if still {
                return (Vec3x4::ZERO, Vec3x4::ZERO);
            }
            // Written out, not `slots.map(..)` (see `Vec3x4::gather`).
            let at = |l: usize| &states[slots[l] as usize];
            let (s0, s1, s2, s3) = (at(0), at(1), at(2), at(3));
            (
                Vec3x4::gather([
                    s0.linear_velocity,
                    s1.linear_velocity,
                    s2.linear_velocity,
                    s3.linear_velocity,
                ]),
                Vec3x4::gather([
                    s0.angular_velocity,
                    s1.angular_velocity,
                    s2.angular_velocity,
                    s3.angular_velocity,
                ]),
            )
        };
        let ((va, wa), (vb, wb)) = (side(a, still[0]), side(b, still[1]));
        Self { va, wa, vb, wb }
    }

    /// Writes the velocities back to slots `bodies`, where `writes` allows (the dynamic bodies
    /// of real lanes: padding lanes repeat lane 0's slots, and static bodies keep theirs); a
    /// side that writes no lane (a still ground) is not even unpacked.
    pub fn store(&self, bodies: &Slots, writes: &[[bool; LANES]; 2], states: &mut [BodyState]) {
        let sides = [(self.va, self.wa), (self.vb, self.wb)];
        for (k, (v, w)) in sides.into_iter().enumerate() {
            if !writes[k].contains(&true) {
                continue;
            }
            let (v, w) = (v.to_vecs(), w.to_vecs());
            for lane in 0..LANES {
                if writes[k][lane] {
                    let s = &mut states[bodies[k][lane] as usize];
                    s.linear_velocity = v[lane];
                    s.angular_velocity = w[lane];
                }
            }
        }
    }
}

/// A 3×3 matrix per lane, by columns.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Mat3x4 {
    /// The columns.
    pub cols: [Vec3x4; 3],
}

impl Mat3x4 {
    /// Lane `i` holds `*m[i]`, read in place (see [`Vec3x4::gather_refs`]).
    #[inline]
    pub fn gather_refs(m: [&Mat3; LANES]) -> Self {
        Self {
            cols: [
                Vec3x4::gather_refs(m.map(|m| &m.x_axis)),
                Vec3x4::gather_refs(m.map(|m| &m.y_axis)),
                Vec3x4::gather_refs(m.map(|m| &m.z_axis)),
            ],
        }
    }

    /// The diagonal matrix of `d` per lane.
    pub fn diagonal(d: Vec3x4) -> Self {
        let zero = Lanes::ZERO;
        let column = |x, y, z| Vec3x4 { x, y, z };
        Self {
            cols: [
                column(d.x, zero, zero),
                column(zero, d.y, zero),
                column(zero, zero, d.z),
            ],
        }
    }

    /// Per-lane matrix times vector.
    pub fn mul_vec(&self, v: Vec3x4) -> Vec3x4 {
        let [x, y, z] = self.cols;
        x * v.x + y * v.y + z * v.z
    }

    /// `[r]× M [r]×` per lane, as [`point_rows`](super::point_rows)'s `skew_sandwich` computes it.
    pub fn skew_sandwich(&self, r: Vec3x4) -> Self {
        let c = self.cols.map(|col| r.cross(col));
        Self {
            cols: [
                c[1] * r.z - c[2] * r.y,
                c[2] * r.x - c[0] * r.z,
                c[0] * r.y - c[1] * r.x,
            ],
        }
    }

    /// Per-lane difference.
    pub fn sub(&self, o: &Self) -> Self {
        Self {
            cols: [0, 1, 2].map(|c| self.cols[c] - o.cols[c]),
        }
    }

    /// The inverse of a symmetric positive semi-definite matrix per lane, as
    /// [`inverse_mass`](super::point_rows::inverse_mass) takes it: the inverse where it is well
    /// conditioned, else the inverse of the diagonal (0 for a non-positive entry).
    pub fn inverse_mass(&self) -> Self {
        let [x, y, z] = self.cols;
        // glam's `Mat3::inverse`: the adjugate's rows are the columns' cross products.
        let (t0, t1, t2) = (y.cross(z), z.cross(x), x.cross(y));
        let det = z.dot(t2);
        let scale = x.x * y.y * z.z;
        let zero = Lanes::ZERO;
        let sound = det.is_finite() & det.simd_gt(Lanes::splat(1e-6) * scale) & scale.simd_gt(zero);
        let inv_det = sound.select(Lanes::ONE / det, zero);
        let row = |t: Vec3x4| t * inv_det;
        let (r0, r1, r2) = (row(t0), row(t1), row(t2));
        let general = [
            Vec3x4 {
                x: r0.x,
                y: r1.x,
                z: r2.x,
            },
            Vec3x4 {
                x: r0.y,
                y: r1.y,
                z: r2.y,
            },
            Vec3x4 {
                x: r0.z,
                y: r1.z,
                z: r2.z,
            },
        ];
        let inv = |d: Lanes| {
            let positive = d.simd_gt(zero);
            positive.select(Lanes::ONE / positive.select(d, Lanes::ONE), zero)
        };
        let diagonal = Self::diagonal(Vec3x4 {
            x: inv(x.x),
            y: inv(y.y),
            z: inv(z.z),
        });
        let pick = |g: Vec3x4, d: Vec3x4| Vec3x4 {
            x: sound.select(g.x, d.x),
            y: sound.select(g.y, d.y),
            z: sound.select(g.z, d.z),
        };
        Self {
            cols: [0, 1, 2].map(|c| pick(general[c], diagonal.cols[c])),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_vectors() -> [Vec3; LANES] {
        [
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(-0.3, 0.7, 4.0),
            Vec3::ZERO,
            Vec3::new(1e3, 1e-3, -7.0),
        ]
    }

    #[test]
    fn lanes_match_glam_dot_and_cross_within_1e_6_relative() {
        let a = sample_vectors();
        let b = a.map(|v| Vec3::new(v.z, v.x + 1.0, -v.y));
        let (wa, wb) = (Vec3x4::gather(a), Vec3x4::gather(b));
        let dots = wa.dot(wb).to_array();
        let cross = wa.cross(wb);
        for i in 0..LANES {
            let scale = a[i].length() * b[i].length() + 1.0;
            assert!((dots[i] - a[i].dot(b[i])).abs() <= 1e-6 * scale);
            assert!((cross.lane(i) - a[i].cross(b[i])).length() <= 1e-6 * scale);
        }
    }

    /// A well-conditioned lane, a singular one (a body turning about one axis only), a
    /// zero one (a padding lane) and a badly scaled one, against the scalar rule.
    #[test]
    fn lanes_invert_effective_masses_as_the_scalar_rule_within_1e_5_relative() {
        use crate::dynamics::solver::point_rows::inverse_mass;
        let m = [
            Mat3::from_cols_array(&[2.0, 0.3, -0.1, 0.3, 1.5, 0.2, -0.1, 0.2, 1.0]),
            Mat3::from_diagonal(Vec3::new(1.0, 0.0, 0.0)),
            Mat3::ZERO,
            Mat3::from_diagonal(Vec3::new(1e4, 2e-3, 7.0)),
        ];
        let wide = Mat3x4::gather_refs(m.each_ref()).inverse_mass();
        for (lane, m) in m.iter().enumerate() {
            let expected = inverse_mass(*m);
            for c in 0..3 {
                let got = wide.cols[c].lane(lane);
                let want = expected.col(c);
                let error = (got - want).length();
                assert!(
                    error <= 1e-5 * (want.length() + 1.0),
                    "lane {lane}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn lanes_rotate_as_glam_within_1e_6_relative() {
        let q = [
            Quat::from_rotation_x(0.3),
            Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 2.5),
            Quat::IDENTITY,
            Quat::from_rotation_z(-3.0),
        ];
        let r = sample_vectors();
        let rotated = Quatx4::gather(q).rotate(Vec3x4::gather(r));
        for i in 0..LANES {
            let error = (rotated.lane(i) - q[i] * r[i]).length();
            assert!(error <= 1e-6 * (r[i].length() + 1.0), "lane {i}: {error}");
        }
    }
}
