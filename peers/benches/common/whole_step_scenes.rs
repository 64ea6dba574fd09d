//! The scenes of `whole_step.rs`, described once and built from the description in both
//! engines: balls (position, velocity), static planes (as half-spaces or 1 m slabs), gravity,
//! friction and restitution.

use glam::Vec3;

/// dt of both engines (urto's default `PhysicsTimestep`, rapier's default `IntegrationParameters`).
pub const DT: f32 = 1.0 / 60.0;
pub const G: f32 = 9.81;
pub const RADIUS: f32 = 0.5;
/// Steps of the `falling_pile` run.
pub const PILE_STEPS: u32 = 300;
/// Steps of the `falling_pile` sanity runs, which go on past the timed ones.
pub const PILE_CHECK_STEPS: u32 = 900;

/// A ball: where it starts and how fast.
#[derive(Clone, Copy, Debug)]
pub struct Ball {
    pub pos: Vec3,
    pub vel: Vec3,
}

/// A static plane: the solid lies on the side opposite to `normal` (a ground, a wall). `point`
/// is the centre of the face the scene uses, `span` half its width: a slab standing for the
/// plane is a 1 m thick box behind that face.
#[derive(Clone, Copy, Debug)]
pub struct Plane {
    pub point: Vec3,
    /// A unit axis (±X, ±Y or ±Z).
    pub normal: Vec3,
    pub span: f32,
}

impl Plane {
    /// Centre and half extents of the slab standing for this plane.
    pub fn slab(&self) -> (Vec3, Vec3) {
        let n = self.normal.abs();
        let half = Vec3::splat(self.span) * (Vec3::ONE - n) + n * (SLAB_THICKNESS / 2.0);
        (self.point - self.normal * (SLAB_THICKNESS / 2.0), half)
    }
}

/// Thickness of the slabs that stand for planes.
pub const SLAB_THICKNESS: f32 = 1.0;

/// How static planes are built in both engines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Walls {
    /// urto `Collider::half_space`, rapier `SharedShape::halfspace`: unbounded, so both engines
    /// pair every ball with every plane.
    HalfSpaces,
    /// A 1 m thick box behind each face: urto `Collider::cuboid` (its static grid), rapier
    /// `ColliderBuilder::cuboid` (its BVH).
    Slabs,
}

/// One scene, built identically in both engines.
#[derive(Clone, Debug)]
pub struct Scene {
    pub balls: Vec<Ball>,
    pub planes: Vec<Plane>,
    pub gravity: Vec3,
    pub friction: f32,
    pub restitution: f32,
    pub walls: Walls,
}

/// A small deterministic generator (the same scene on every run; the one of urto's examples).
pub struct Lcg(u64);

impl Lcg {
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((self.0 >> 40) as f32 / (1u64 << 24) as f32)
    }
}

/// `n` balls resting on a ground at z = 0, on a square grid 2 m apart (1 m gaps).
pub fn resting(n: usize, walls: Walls) -> Scene {
    let side = (n as f32).sqrt().ceil() as usize;
    let balls = (0..n)
        .map(|i| Ball {
            pos: Vec3::new((i % side) as f32 * 2.0, (i / side) as f32 * 2.0, RADIUS),
            vel: Vec3::ZERO,
        })
        .collect();
    let centre = (side - 1) as f32;
    Scene {
        balls,
        planes: vec![Plane {
            point: Vec3::new(centre, centre, 0.0),
            normal: Vec3::Z,
            span: side as f32 + 2.0,
        }],
        gravity: Vec3::new(0.0, 0.0, -G),
        friction: 0.5,
        restitution: 0.0,
        walls,
    }
}

/// Half the inner width of the `falling_pile` box.
pub const PILE_HALF: f32 = 6.0;
/// Height of the `falling_pile` box's walls.
pub const PILE_HEIGHT: f32 = 14.0;

/// 1000 balls in a 10 × 10 × 10 grid 1.2 m apart (0.2 m gaps), ±5 cm of jitter on each axis,
/// the lowest layer 1 m above the ground, each ball with a random horizontal velocity of up to
/// 1 m/s per axis (so that the columns do not just stack: they cross and pile up), in an open
/// 12 × 12 m box (a ground and four walls).
pub fn falling_pile(walls: Walls) -> Scene {
    let mut rng = Lcg::new(7);
    let mut balls = Vec::with_capacity(1000);
    for k in 0..10 {
        for j in 0..10 {
            for i in 0..10 {
                let jitter = Vec3::new(
                    rng.range(-0.05, 0.05),
                    rng.range(-0.05, 0.05),
                    rng.range(-0.05, 0.05),
                );
                let at = Vec3::new(
                    -PILE_HALF + 0.6 + i as f32 * 1.2,
                    -PILE_HALF + 0.6 + j as f32 * 1.2,
                    1.0 + k as f32 * 1.2,
                );
                let vel = Vec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0);
                balls.push(Ball {
                    pos: at + jitter,
                    vel,
                });
            }
        }
    }
    let (h, zc) = (PILE_HALF, PILE_HEIGHT / 2.0);
    let span = PILE_HEIGHT / 2.0 + 0.5;
    Scene {
        balls,
        planes: vec![
            plane(Vec3::ZERO, Vec3::Z, h + 1.0),
            plane(Vec3::new(-h, 0.0, zc), Vec3::X, span),
            plane(Vec3::new(h, 0.0, zc), -Vec3::X, span),
            plane(Vec3::new(0.0, -h, zc), Vec3::Y, span),
            plane(Vec3::new(0.0, h, zc), -Vec3::Y, span),
        ],
        gravity: Vec3::new(0.0, 0.0, -G),
        friction: 0.5,
        restitution: 0.0,
        walls,
    }
}

pub fn plane(point: Vec3, normal: Vec3, span: f32) -> Plane {
    Plane {
        point,
        normal,
        span,
    }
}

/// Spacing of the `sparse_movers` grid.
pub const SPARSE_SPACING: f32 = 4.0;

/// `n` balls on a cubic grid 4 m apart with ±1 m of jitter, velocities uniform in ±5 m/s per
/// axis (at first up to 0.14 m per step: a seventh of a diameter), no gravity, inside a closed
/// box (six planes, 2 m beyond the outermost cells), restitution 1 and no friction so the motion
/// goes on.
pub fn sparse_movers(n: usize, walls: Walls) -> Scene {
    let side = (n as f32).cbrt().ceil() as usize;
    let mut rng = Lcg::new(11);
    let balls = (0..n)
        .map(|i| {
            let cell = Vec3::new(
                (i % side) as f32,
                ((i / side) % side) as f32,
                (i / (side * side)) as f32,
            );
            let jitter = Vec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            let vel = Vec3::new(
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
            );
            Ball {
                pos: cell * SPARSE_SPACING + jitter,
                vel,
            }
        })
        .collect();
    let lo = -SPARSE_SPACING / 2.0;
    let hi = (side as f32 - 0.5) * SPARSE_SPACING;
    let centre = Vec3::splat((lo + hi) / 2.0);
    let span = (hi - lo) / 2.0 + SLAB_THICKNESS;
    let mut planes = Vec::new();
    for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
        let on = |v: f32| centre * (Vec3::ONE - axis) + axis * v;
        planes.push(plane(on(lo), axis, span));
        planes.push(plane(on(hi), -axis, span));
    }
    Scene {
        balls,
        planes,
        gravity: Vec3::ZERO,
        friction: 0.0,
        restitution: 1.0,
        walls,
    }
}

// ---------------------------------------------------------------- urto
