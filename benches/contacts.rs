//! Narrow-phase throughput for the primitive pairs, against parry3d 0.31 on the same poses.
//!
//! Each benchmark runs one query per pose over a fixed, seeded set of poses (about half of them
//! overlapping), so the time per iteration divided by `POSES` is the cost of one pair test.
//! Rivals: parry's `query::contact` (one point; GJK/EPA for box–box) and, for box–box, parry's
//! `contact_manifold_cuboid_cuboid` (the manifold rapier uses; cleared before each call so that
//! its frame-to-frame cache does not skip the work).

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Quat, Vec3};
use std::hint::black_box;
use urto::geometry::contacts::{
    contact, contact_cuboid_cuboid, contact_cuboid_halfspace, contact_sphere_cuboid,
};
use urto::geometry::{Cuboid, HalfSpace, Isometry, Shape, Sphere};

/// Poses per benchmark iteration.
const POSES: usize = 1024;

/// SplitMix64: seeded, so every run measures the same poses.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    fn vec(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next()) * (hi - lo) + Vec3::splat(lo)
    }

    fn pose(&mut self, reach: f32) -> Isometry {
        let q = Quat::from_xyzw(
            self.next() - 0.5,
            self.next() - 0.5,
            self.next() - 0.5,
            self.next() - 0.5,
        );
        Isometry::new(self.vec(-reach, reach), q.normalize())
    }
}

fn parry_pose(p: &Isometry) -> parry3d::math::Pose {
    parry3d::math::Pose::from_parts(
        parry3d::math::Vector::from_array(p.translation.to_array()),
        parry3d::math::Rot3::from_array(p.rotation.to_array()),
    )
}

fn parry_cuboid(c: &Cuboid) -> parry3d::shape::Cuboid {
    parry3d::shape::Cuboid::new(parry3d::math::Vector::from_array(c.half_extents.to_array()))
}

struct Scene<A, B> {
    pairs: Vec<(A, Isometry, B, Isometry)>,
}

fn box_pairs() -> Scene<Cuboid, Cuboid> {
    let mut r = Rng(1);
    let pairs = (0..POSES)
        .map(|_| {
            let a = Cuboid {
                half_extents: r.vec(0.1, 1.5),
            };
            let b = Cuboid {
                half_extents: r.vec(0.1, 1.5),
            };
            (a, r.pose(1.5), b, r.pose(1.5))
        })
        .collect();
    Scene { pairs }
}

fn cuboid_cuboid(c: &mut Criterion) {
    let scene = box_pairs();
    let parry: Vec<_> = scene
        .pairs
        .iter()
        .map(|(a, pa, b, pb)| {
            (
                parry_cuboid(a),
                parry_pose(pa),
                parry_cuboid(b),
                parry_pose(pb),
            )
        })
        .collect();
    let mut group = c.benchmark_group("cuboid_cuboid");
    group.bench_function("urto manifold (SAT + clipping)", |bench| {
        bench.iter(|| {
            for (a, pa, b, pb) in &scene.pairs {
                black_box(contact_cuboid_cuboid(pa, a, pb, b));
            }
        })
    });
    group.bench_function("parry contact_manifold_cuboid_cuboid", |bench| {
        let mut manifold = parry3d::query::ContactManifold::<(), ()>::new();
        bench.iter(|| {
            for (a, pa, b, pb) in &parry {
                manifold.clear();
                let pos12 = pa.inv_mul(pb);
                parry3d::query::details::contact_manifold_cuboid_cuboid(
                    &pos12,
                    a,
                    b,
                    0.0,
                    &mut manifold,
                );
                black_box(manifold.points.len());
            }
        })
    });
    group.bench_function("parry query::contact (one point, GJK/EPA)", |bench| {
        bench.iter(|| {
            for (a, pa, b, pb) in &parry {
                black_box(parry3d::query::contact(pa, a, pb, b, 0.0).ok());
            }
        })
    });
    group.finish();
}

fn sphere_cuboid(c: &mut Criterion) {
    let mut r = Rng(2);
    let pairs: Vec<_> = (0..POSES)
        .map(|_| {
            let s = Sphere {
                radius: 0.1 + r.next() * 1.4,
            };
            let b = Cuboid {
                half_extents: r.vec(0.1, 1.5),
            };
            (s, r.pose(1.0), b, r.pose(1.0))
        })
        .collect();
    let parry: Vec<_> = pairs
        .iter()
        .map(|(s, ps, b, pb)| {
            (
                parry3d::shape::Ball::new(s.radius),
                parry_pose(ps),
                parry_cuboid(b),
                parry_pose(pb),
            )
        })
        .collect();
    let mut group = c.benchmark_group("sphere_cuboid");
    group.bench_function("urto", |bench| {
        bench.iter(|| {
            for (s, ps, b, pb) in &pairs {
                black_box(contact_sphere_cuboid(ps.translation, s, pb, b));
            }
        })
    });
    group.bench_function("parry query::contact", |bench| {
        bench.iter(|| {
            for (s, ps, b, pb) in &parry {
                black_box(parry3d::query::contact(ps, s, pb, b, 0.0).ok());
            }
        })
    });
    group.finish();
}

fn cuboid_halfspace(c: &mut Criterion) {
    let mut r = Rng(3);
    let pairs: Vec<_> = (0..POSES)
        .map(|_| {
            let b = Cuboid {
                half_extents: r.vec(0.1, 1.5),
            };
            let h = HalfSpace {
                normal: r.vec(-1.0, 1.0).normalize_or(Vec3::Z),
            };
            (b, r.pose(1.0), h, r.pose(1.0))
        })
        .collect();
    let parry: Vec<_> = pairs
        .iter()
        .map(|(b, pb, h, ph)| {
            let normal = parry3d::math::Vector::from_array(h.normal.to_array());
            (
                parry_cuboid(b),
                parry_pose(pb),
                parry3d::shape::HalfSpace::new(normal),
                parry_pose(ph),
            )
        })
        .collect();
    let mut group = c.benchmark_group("cuboid_halfspace");
    group.bench_function("urto manifold (up to 4 vertices)", |bench| {
        bench.iter(|| {
            for (b, pb, h, ph) in &pairs {
                black_box(contact_cuboid_halfspace(pb, b, ph, h));
            }
        })
    });
    // Half-space first: parry 0.31.1's (box, half-space) order has a pose bug (see the oracle
    // test), and the cost is the same either way.
    group.bench_function("parry query::contact (one point)", |bench| {
        bench.iter(|| {
            for (b, pb, h, ph) in &parry {
                black_box(parry3d::query::contact(ph, h, pb, b, 0.0).ok());
            }
        })
    });
    group.finish();
}

/// Pairs without a closed form: a random hull of 16 points against another, and a cylinder
/// against a box. urto builds the whole manifold (GJK/EPA, then the feature clip). parry is
/// timed twice: `query::contact` finds one point by GJK/EPA (less work than a manifold), and
/// its contact-manifold dispatcher builds a manifold as rapier does (GJK/EPA, then the
/// polygonal features clipped: the same work), each call from an empty manifold with no
/// normal to start from, as a new pair has.
fn convex_pairs(c: &mut Criterion) {
    let mut r = Rng(4);
    let hull = |r: &mut Rng| {
        let half = r.vec(0.2, 1.0);
        let points: Vec<Vec3> = (0..16).map(|_| r.vec(-1.0, 1.0) * half).collect();
        Shape::convex_hull(&points).unwrap_or_else(|_| Shape::cuboid(half))
    };
    let hulls: Vec<_> = (0..POSES)
        .map(|_| (hull(&mut r), r.pose(1.0), hull(&mut r), r.pose(1.0)))
        .collect();
    let cylinders: Vec<_> = (0..POSES)
        .map(|_| {
            let cyl = Shape::cylinder(0.1 + r.next(), 0.1 + r.next());
            (
                cyl,
                r.pose(1.0),
                Shape::cuboid(r.vec(0.1, 1.0)),
                r.pose(1.0),
            )
        })
        .collect();
    let to_parry = |s: &Shape| -> Box<dyn parry3d::shape::Shape> {
        match s {
            Shape::ConvexHull(h) => {
                let v: Vec<_> = h
                    .vertices()
                    .iter()
                    .map(|p| parry3d::math::Vector::from_array(p.to_array()))
                    .collect();
                Box::new(parry3d::shape::ConvexPolyhedron::from_convex_hull(&v).unwrap())
            }
            Shape::Cylinder(c) => Box::new(parry3d::shape::Cylinder::new(c.half_height, c.radius)),
            Shape::Cuboid(c) => Box::new(parry_cuboid(c)),
            _ => unreachable!(),
        }
    };
    let mut group = c.benchmark_group("convex");
    for (name, pairs) in [("hull_hull", &hulls), ("cylinder_cuboid", &cylinders)] {
        let parry: Vec<_> = pairs
            .iter()
            .map(|(a, pa, b, pb)| (to_parry(a), parry_pose(pa), to_parry(b), parry_pose(pb)))
            .collect();
        group.bench_function(format!("{name}: urto manifold (GJK/EPA + clip)"), |bench| {
            bench.iter(|| {
                for (a, pa, b, pb) in pairs {
                    black_box(contact(a, pa, b, pb));
                }
            })
        });
        group.bench_function(
            format!("{name}: parry query::contact (one point)"),
            |bench| {
                bench.iter(|| {
                    for (a, pa, b, pb) in &parry {
                        black_box(parry3d::query::contact(pa, &**a, pb, &**b, 0.0).ok());
                    }
                })
            },
        );
        group.bench_function(
            format!("{name}: parry manifold (GJK/EPA + clip)"),
            |bench| {
                use parry3d::query::{ContactManifold, PersistentQueryDispatcher};
                let dispatcher = parry3d::query::DefaultQueryDispatcher;
                let mut manifold = ContactManifold::<(), ()>::new();
                bench.iter(|| {
                    for (a, pa, b, pb) in &parry {
                        manifold.clear();
                        manifold.local_n1 = parry3d::math::Vector::ZERO;
                        let _ = dispatcher.contact_manifold_convex_convex(
                            &pa.inv_mul(pb),
                            &**a,
                            &**b,
                            None,
                            None,
                            0.0,
                            &mut manifold,
                        );
                        black_box(manifold.points.len());
                    }
                })
            },
        );
    }
    group.finish();
}

criterion_group!(
    benches,
    cuboid_cuboid,
    sphere_cuboid,
    cuboid_halfspace,
    convex_pairs
);
criterion_main!(benches);
