//! A plain separating-axis triangle–triangle test, the reference leaf test of the BVH tests (the
//! production test lives elsewhere).
//!
//! Two triangles (closed, possibly degenerate) are disjoint iff some axis separates their
//! projections. Candidates: both normals, the 9 cross products of an edge of each, and the 6
//! in-plane edge normals `n × e` that settle the coplanar case. An axis that is (near) zero is
//! skipped. Any candidate that separates proves disjointness, so the test never reports "apart"
//! for touching triangles; for degenerate triangles it may report "intersecting" for some
//! disjoint pairs, which is harmless here (the BVH and the brute force call the same test).

use glam::Vec3;

fn interval(t: &[Vec3; 3], axis: Vec3) -> (f32, f32) {
    let d = [axis.dot(t[0]), axis.dot(t[1]), axis.dot(t[2])];
    (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]))
}

fn separates(a: &[Vec3; 3], b: &[Vec3; 3], axis: Vec3) -> bool {
    if axis.length_squared() <= 1e-20 {
        return false;
    }
    let (a0, a1) = interval(a, axis);
    let (b0, b1) = interval(b, axis);
    a1 < b0 || b1 < a0
}

pub fn triangles_intersect(a: &[Vec3; 3], b: &[Vec3; 3]) -> bool {
    // Cheap reject first: the triangles' boxes.
    let (amin, amax) = (a[0].min(a[1]).min(a[2]), a[0].max(a[1]).max(a[2]));
    let (bmin, bmax) = (b[0].min(b[1]).min(b[2]), b[0].max(b[1]).max(b[2]));
    if amax.cmplt(bmin).any() || bmax.cmplt(amin).any() {
        return false;
    }
    let ea = [a[1] - a[0], a[2] - a[1], a[0] - a[2]];
    let eb = [b[1] - b[0], b[2] - b[1], b[0] - b[2]];
    let na = ea[0].cross(ea[1]);
    let nb = eb[0].cross(eb[1]);
    if separates(a, b, na) || separates(a, b, nb) {
        return false;
    }
    for x in ea {
        for y in eb {
            if separates(a, b, x.cross(y)) {
                return false;
            }
        }
    }
    for e in ea {
        if separates(a, b, na.cross(e)) {
            return false;
        }
    }
    for e in eb {
        if separates(a, b, nb.cross(e)) {
            return false;
        }
    }
    true
}
