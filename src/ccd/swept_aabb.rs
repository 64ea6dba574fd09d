//! The swept AABB: the box holding a translating body over a whole step, the union of its boxes
//! at the start and at the end. Since the motion is a translation, every intermediate box lies
//! inside that union, so a broad phase fed with swept boxes finds every pair that may touch
//! during the step — the candidates of continuous collision — at the cost of a larger box.

use crate::bounding::Aabb;
use glam::Vec3;

/// The box holding `start` translated by every `t·displacement`, `t ∈ [0, 1]`.
pub fn swept_aabb(start: &Aabb, displacement: Vec3) -> Aabb {
    let end = Aabb::new(start.min + displacement, start.max + displacement);
    start.union(&end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_every_intermediate_box_and_nothing_more_than_the_ends() {
        let start = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(0.0, 1.0, 3.0));
        let d = Vec3::new(3.0, -2.0, 0.5);
        let swept = swept_aabb(&start, d);
        for i in 0..=16 {
            let t = i as f32 / 16.0;
            let moved = Aabb::new(start.min + d * t, start.max + d * t);
            assert!(swept.expanded(1e-6).contains(&moved), "t = {t}");
        }
        assert_eq!(swept.min, Vec3::new(-1.0, -2.0, 2.0));
        assert_eq!(swept.max, Vec3::new(3.0, 1.0, 3.5));
        assert_eq!(swept_aabb(&start, Vec3::ZERO), start);
    }
}
