//! The broad phases against an independent model: random sequences of inserts, bulk inserts,
//! moves (jitter and jumps on a coarse grid, so boxes touch and values repeat, `-0.0`
//! included), removals, static bodies and bad calls; after every commit each broad phase's
//! pairs, added and removed must equal the model's brute-force answer exactly. And the
//! incremental SAP allocates nothing per step once its buffers have grown (a counting
//! allocator, issue 12).

use crate::common::rng::Rng;
use glam::Vec3;
use proptest::prelude::*;
use std::collections::{BTreeMap, BTreeSet};
use urto::bounding::Aabb;
use urto::broad_phase::{
    AdaptiveSweep, AxisBits, AxisTests, BodyKind, BroadPhase, BroadPhaseError, BruteForce,
    IncrementalSap, MAX_PROXY_ID, Pair, ProxyId, RegionSweep, SortAndSweep,
};

// ---------------------------------------------------------------- the subjects

/// Every broad phase under test, fed the same calls.
struct Subjects {
    brute: BruteForce,
    sweep: SortAndSweep,
    /// Default, always whole-array insertion sort, never.
    tests: [IncrementalSap<AxisTests>; 3],
    /// Default, always whole-array insertion sort.
    bits: [IncrementalSap<AxisBits>; 2],
    /// The SAP that falls back to sorting from scratch.
    adaptive: AdaptiveSweep,
    /// Segmented sweep and prune.
    regions: RegionSweep,
}

impl Subjects {
    fn new() -> Self {
        Self {
            brute: BruteForce::new(),
            sweep: SortAndSweep::new(),
            tests: [
                IncrementalSap::new(),
                IncrementalSap::new().with_full_sort_fraction(0.0),
                IncrementalSap::new().with_full_sort_fraction(f32::INFINITY),
            ],
            bits: [
                IncrementalSap::new(),
                IncrementalSap::new().with_full_sort_fraction(0.0),
            ],
            adaptive: AdaptiveSweep::new(),
            regions: RegionSweep::new(),
        }
    }

    fn all(&mut self) -> Vec<(&'static str, &mut dyn BroadPhase)> {
        let [t0, t1, t2] = &mut self.tests;
        let [b0, b1] = &mut self.bits;
        vec![
            ("brute", &mut self.brute as &mut dyn BroadPhase),
            ("sort-sweep", &mut self.sweep),
            ("sap-tests", t0),
            ("sap-tests-full-sort", t1),
            ("sap-tests-per-body", t2),
            ("sap-bits", b0),
            ("sap-bits-full-sort", b1),
            ("adaptive", &mut self.adaptive),
            ("regions", &mut self.regions),
        ]
    }

    /// Applies one call to every subject; all must give the same result.
    fn apply(
        &mut self,
        call: impl Fn(&mut dyn BroadPhase) -> Result<(), BroadPhaseError>,
    ) -> Result<(), BroadPhaseError> {
        let results: Vec<_> = self
            .all()
            .into_iter()
            .map(|(name, bp)| (name, call(bp)))
            .collect();
        for (name, result) in &results[1..] {
            assert_eq!(*result, results[0].1, "{name} disagrees with brute force");
        }
        results[0].1
    }

    fn check_internals(&self) {
        for sap in &self.tests {
            sap.check_consistency().unwrap();
        }
        for sap in &self.bits {
            sap.check_consistency().unwrap();
        }
    }
}

// ---------------------------------------------------------------- the model

/// What the broad phases should know: each live body's box and whether it is static.
#[derive(Default)]
struct Model {
    bodies: BTreeMap<ProxyId, (Aabb, bool)>,
    pairs: BTreeSet<Pair>,
}

impl Model {
    /// All intersecting pairs except static–static, by brute force over `Aabb::intersects`.
    fn expected_pairs(&self) -> BTreeSet<Pair> {
        let bodies: Vec<_> = self.bodies.iter().collect();
        let mut pairs = BTreeSet::new();
        for (i, (ia, (a, a_static))) in bodies.iter().enumerate() {
            for (ib, (b, b_static)) in &bodies[i + 1..] {
                if !(*a_static && *b_static) && a.intersects(b) {
                    pairs.insert(Pair::new(**ia, **ib).unwrap());
                }
            }
        }
        pairs
    }

    fn box_is_bad(aabb: &Aabb) -> bool {
        !aabb.is_finite() || !aabb.is_valid()
    }
}

// ---------------------------------------------------------------- the calls

#[derive(Clone, Debug)]
enum Op {
    Insert(ProxyId, Aabb, bool),
    InsertBulk(Vec<(ProxyId, Aabb, bool)>),
    Jitter(ProxyId, Vec3),
    Jump(ProxyId, Aabb),
    Remove(ProxyId),
    Commit,
}

fn kind(is_static: bool) -> BodyKind {
    if is_static {
        BodyKind::Static
    } else {
        BodyKind::Dynamic
    }
}

/// Quarter-unit grid coordinates, with both zeros.
fn coordinate() -> impl Strategy<Value = f32> + Clone {
    prop_oneof![10 => (-12i32..=12).prop_map(|k| k as f32 * 0.25), 1 => Just(-0.0f32)]
}

/// Mostly grid boxes (touching and repeated values are common); sometimes a bad one.
fn any_box() -> impl Strategy<Value = Aabb> + Clone {
    let size = prop_oneof![Just(0.0f32), Just(0.25), Just(0.5), Just(1.0), Just(2.0)];
    let good = (
        coordinate(),
        coordinate(),
        coordinate(),
        size.clone(),
        size.clone(),
        size,
    )
        .prop_map(|(x, y, z, sx, sy, sz)| {
            let min = Vec3::new(x, y, z);
            Aabb::new(min, min + Vec3::new(sx, sy, sz))
        });
    let bad = prop_oneof![
        Just(Aabb::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ONE)),
        Just(Aabb::new(Vec3::ZERO, Vec3::new(1.0, f32::INFINITY, 1.0))),
        Just(Aabb::new(
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 1.0, 0.5)
        )),
    ];
    prop_oneof![40 => good, 1 => bad]
}

fn id() -> impl Strategy<Value = ProxyId> + Clone {
    prop_oneof![30 => 0u32..20, 1 => Just(700u32), 1 => Just(MAX_PROXY_ID + 1)]
}

fn jitter() -> impl Strategy<Value = Vec3> {
    let step = prop_oneof![
        Just(-1.0f32),
        Just(-0.25),
        Just(-0.05),
        Just(0.0),
        Just(0.05),
        Just(0.25),
        Just(1.0)
    ];
    (step.clone(), step.clone(), step).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

fn op() -> impl Strategy<Value = Op> {
    let body = (id(), any_box(), prop::bool::weighted(0.2));
    prop_oneof![
        4 => body.clone().prop_map(|(i, b, s)| Op::Insert(i, b, s)),
        1 => prop::collection::vec(body, 0..8).prop_map(Op::InsertBulk),
        6 => (id(), jitter()).prop_map(|(i, d)| Op::Jitter(i, d)),
        2 => (id(), any_box()).prop_map(|(i, b)| Op::Jump(i, b)),
        2 => id().prop_map(Op::Remove),
        3 => Just(Op::Commit),
    ]
}

// ---------------------------------------------------------------- running a sequence

/// Applies one call to the model (returning whether it should succeed) and to the subjects.
fn run_op(op: &Op, model: &mut Model, subjects: &mut Subjects) {
    let live = |model: &Model, id| model.bodies.contains_key(&id);
    let expect_ok = match op {
        Op::Insert(id, aabb, _) => {
            *id <= MAX_PROXY_ID && !Model::box_is_bad(aabb) && !live(model, *id)
        }
        Op::InsertBulk(items) => {
            let ids: BTreeSet<_> = items.iter().map(|i| i.0).collect();
            ids.len() == items.len()
                && items.iter().all(|(id, b, _)| {
                    *id <= MAX_PROXY_ID && !Model::box_is_bad(b) && !live(model, *id)
                })
        }
        Op::Jitter(id, _) | Op::Jump(id, _) | Op::Remove(id) => live(model, *id),
        Op::Commit => true,
    };
    let result = match op {
        Op::Insert(id, aabb, s) => subjects.apply(|bp| bp.insert(*id, *aabb, kind(*s))),
        Op::InsertBulk(items) => {
            let items: Vec<_> = items.iter().map(|&(i, b, s)| (i, b, kind(s))).collect();
            subjects.apply(|bp| bp.insert_bulk(&items))
        }
        Op::Jitter(id, d) => {
            let moved = model
                .bodies
                .get(id)
                .map_or(Aabb::new(Vec3::ZERO, Vec3::ONE), |(b, _)| {
                    Aabb::new(b.min + *d, b.max + *d)
                });
            let result = subjects.apply(|bp| bp.update(*id, moved));
            if result.is_ok() {
                model.bodies.get_mut(id).unwrap().0 = moved;
            }
            result
        }
        Op::Jump(id, aabb) => {
            let result = subjects.apply(|bp| bp.update(*id, *aabb));
            assert_eq!(result.is_ok(), live(model, *id) && !Model::box_is_bad(aabb));
            if result.is_ok() {
                model.bodies.get_mut(id).unwrap().0 = *aabb;
            }
            return;
        }
        Op::Remove(id) => subjects.apply(|bp| bp.remove(*id)),
        Op::Commit => {
            commit_and_compare(model, subjects);
            Ok(())
        }
    };
    assert_eq!(result.is_ok(), expect_ok, "{op:?} gave {result:?}");
    if result.is_ok() {
        match op {
            Op::Insert(id, aabb, s) => {
                model.bodies.insert(*id, (*aabb, *s));
            }
            Op::InsertBulk(items) => model
                .bodies
                .extend(items.iter().map(|&(i, b, s)| (i, (b, s)))),
            Op::Remove(id) => {
                model.bodies.remove(id);
            }
            _ => {}
        }
    }
    check_bodies(model, subjects);
}

/// Between commits every subject must already report the recorded bodies.
fn check_bodies(model: &Model, subjects: &mut Subjects) {
    for (name, bp) in subjects.all() {
        assert_eq!(bp.len(), model.bodies.len(), "{name}: len");
        for (id, (aabb, _)) in &model.bodies {
            assert!(bp.contains(*id), "{name}: lost {id}");
            assert_eq!(bp.aabb(*id), Some(*aabb), "{name}: box of {id}");
        }
    }
}

/// Commits every subject and compares pairs, added and removed with the model.
fn commit_and_compare(model: &mut Model, subjects: &mut Subjects) {
    let expected = model.expected_pairs();
    let added: Vec<Pair> = expected.difference(&model.pairs).copied().collect();
    let removed: Vec<Pair> = model.pairs.difference(&expected).copied().collect();
    let expected_list: Vec<Pair> = expected.iter().copied().collect();
    let mut sorted = Vec::new();
    for (name, bp) in subjects.all() {
        bp.commit();
        bp.sorted_pairs_into(&mut sorted);
        assert_eq!(sorted, expected_list, "{name}: pairs");
        assert_eq!(bp.added(), &added[..], "{name}: added");
        assert_eq!(bp.removed(), &removed[..], "{name}: removed");
    }
    subjects.check_internals();
    model.pairs = expected;
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn every_broad_phase_matches_brute_force_after_every_commit(ops in prop::collection::vec(op(), 1..80)) {
        let mut model = Model::default();
        let mut subjects = Subjects::new();
        for op in &ops {
            run_op(op, &mut model, &mut subjects);
        }
        commit_and_compare(&mut model, &mut subjects);
    }
}

// ---------------------------------------------------------------- larger scenes

#[test]
fn a_thousand_moving_bodies_match_sort_and_sweep_and_orders_are_reproducible() {
    let mut rng = Rng::new(0x1234_5678_9abc_def1);
    let side = 14.0;
    let bodies: Vec<(ProxyId, Aabb, BodyKind)> = (0..1000)
        .map(|i| {
            let c = rng.vec3(0.0, side);
            let kind = if i % 10 == 0 {
                BodyKind::Static
            } else {
                BodyKind::Dynamic
            };
            (i, Aabb::from_center_half_extents(c, Vec3::splat(0.5)), kind)
        })
        .collect();
    let mut reference = SortAndSweep::new();
    let mut sap = IncrementalSap::<AxisTests>::new();
    let mut twin = IncrementalSap::<AxisTests>::new();
    for bp in [&mut reference as &mut dyn BroadPhase, &mut sap, &mut twin] {
        bp.insert_bulk(&bodies).unwrap();
        bp.commit();
    }
    let (mut expected, mut got) = (Vec::new(), Vec::new());
    for step in 0..40 {
        let speed = if step % 10 == 9 { 3.0 } else { 0.1 };
        for &(id, _, _) in bodies.iter().filter(|b| (b.0 + step) % 3 == 0) {
            let b = sap.aabb(id).unwrap();
            let d = rng.vec3(-speed, speed);
            let moved = Aabb::new(b.min + d, b.max + d);
            for bp in [&mut reference as &mut dyn BroadPhase, &mut sap, &mut twin] {
                bp.update(id, moved).unwrap();
            }
        }
        for bp in [&mut reference as &mut dyn BroadPhase, &mut sap, &mut twin] {
            bp.commit();
        }
        reference.sorted_pairs_into(&mut expected);
        sap.sorted_pairs_into(&mut got);
        assert!(
            expected.len() > 100,
            "the scene should have pairs ({})",
            expected.len()
        );
        assert_eq!(got, expected, "step {step}");
        assert_eq!(sap.added(), reference.added());
        assert_eq!(sap.removed(), reference.removed());
        assert_eq!(sap.pairs(), twin.pairs(), "same calls, same order");
        sap.check_consistency().unwrap();
    }
    assert!(sap.stats().endpoint_swaps > 0);
}

// ---------------------------------------------------------------- bad calls

fn unit_box(x: f32) -> Aabb {
    Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))
}

/// Every bad call is refused with the right error and changes nothing.
#[test]
fn bad_calls_are_refused_and_leave_the_structure_intact() {
    let nan = Aabb::new(Vec3::new(0.0, f32::NAN, 0.0), Vec3::ONE);
    let infinite = Aabb::new(Vec3::ZERO, Vec3::new(f32::INFINITY, 1.0, 1.0));
    let inverted = Aabb::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 1.0));
    let mut subjects = Subjects::new();
    for (_, bp) in subjects.all() {
        bp.insert(0, unit_box(0.0), BodyKind::Dynamic).unwrap();
        bp.insert(1, unit_box(0.5), BodyKind::Dynamic).unwrap();
        bp.insert(2, unit_box(5.0), BodyKind::Static).unwrap();
        bp.commit();
        let bad_calls: Vec<(Result<(), BroadPhaseError>, BroadPhaseError)> = vec![
            (
                bp.insert(3, nan, BodyKind::Dynamic),
                BroadPhaseError::NonFiniteAabb(3),
            ),
            (
                bp.insert(3, infinite, BodyKind::Dynamic),
                BroadPhaseError::NonFiniteAabb(3),
            ),
            (
                bp.insert(3, inverted, BodyKind::Dynamic),
                BroadPhaseError::InvertedAabb(3),
            ),
            (
                bp.insert(1, unit_box(9.0), BodyKind::Dynamic),
                BroadPhaseError::DuplicateId(1),
            ),
            (
                bp.insert(MAX_PROXY_ID + 1, unit_box(9.0), BodyKind::Dynamic),
                BroadPhaseError::IdOutOfRange(MAX_PROXY_ID + 1),
            ),
            (bp.update(7, unit_box(0.0)), BroadPhaseError::UnknownId(7)),
            (bp.update(1, nan), BroadPhaseError::NonFiniteAabb(1)),
            (bp.update(1, inverted), BroadPhaseError::InvertedAabb(1)),
            (bp.remove(7), BroadPhaseError::UnknownId(7)),
            (
                bp.insert_bulk(&[
                    (4, unit_box(0.2), BodyKind::Dynamic),
                    (4, unit_box(0.3), BodyKind::Dynamic),
                ]),
                BroadPhaseError::DuplicateId(4),
            ),
            (
                bp.insert_bulk(&[
                    (4, unit_box(0.2), BodyKind::Dynamic),
                    (5, nan, BodyKind::Dynamic),
                ]),
                BroadPhaseError::NonFiniteAabb(5),
            ),
            (
                bp.insert_bulk(&[
                    (4, unit_box(0.2), BodyKind::Dynamic),
                    (0, unit_box(0.3), BodyKind::Dynamic),
                ]),
                BroadPhaseError::DuplicateId(0),
            ),
        ];
        for (result, error) in bad_calls {
            assert_eq!(result, Err(error));
        }
        assert_eq!(bp.len(), 3);
        assert_eq!(bp.aabb(1), Some(unit_box(0.5)));
        assert!(!bp.contains(3) && !bp.contains(4));
        bp.commit();
        assert_eq!(bp.pairs(), &[Pair { a: 0, b: 1 }]);
        assert!(bp.added().is_empty() && bp.removed().is_empty());
    }
    subjects.check_internals();
}

#[test]
fn removing_and_reinserting_in_one_step_reports_only_net_changes() {
    let mut subjects = Subjects::new();
    for (name, bp) in subjects.all() {
        bp.insert(0, unit_box(0.0), BodyKind::Dynamic).unwrap();
        bp.insert(1, unit_box(0.5), BodyKind::Dynamic).unwrap();
        bp.insert(2, unit_box(3.0), BodyKind::Dynamic).unwrap();
        bp.commit();
        // 1 leaves and comes back still touching 0, and as a static now touching 2 instead.
        bp.remove(1).unwrap();
        bp.insert(1, unit_box(1.0), BodyKind::Dynamic).unwrap();
        bp.remove(1).unwrap();
        bp.insert(1, unit_box(2.0), BodyKind::Static).unwrap();
        bp.commit();
        assert_eq!(bp.added(), &[Pair { a: 1, b: 2 }], "{name}");
        assert_eq!(bp.removed(), &[Pair { a: 0, b: 1 }], "{name}");
        // 0 passes right through 1 and 2 within one step (one update): no change at all.
        bp.update(0, unit_box(10.0)).unwrap();
        bp.commit();
        assert_eq!(bp.added(), &[] as &[Pair], "{name}");
        assert_eq!(bp.removed(), &[] as &[Pair], "{name}");
        assert_eq!(bp.pairs(), &[Pair { a: 1, b: 2 }], "{name}");
    }
    subjects.check_internals();
}

// ------------------------------------------- no allocation per step in steady state

/// Counts the allocations each thread makes (tests run on threads of their own, so a test
/// reads only its own count).
struct CountingAllocator;

thread_local! {
    static ALLOCATIONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

fn count_allocation() {
    // `try_with`: a thread being torn down still frees and may allocate.
    let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
}

// SAFETY: every call is forwarded unchanged to the system allocator; only a counter is added.
unsafe impl std::alloc::GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        count_allocation();
        // SAFETY: the caller's contract for `alloc` is the system allocator's.
        unsafe { std::alloc::System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        // SAFETY: `ptr` came from `alloc`/`realloc` above, i.e. from the system allocator.
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new_size: usize) -> *mut u8 {
        count_allocation();
        // SAFETY: as for `dealloc`, and `new_size` is the caller's.
        unsafe { std::alloc::System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

pub(super) fn allocations() -> u64 {
    ALLOCATIONS.with(|n| n.get())
}

/// 2,000 unit boxes on a 1.5 m lattice, each swinging on its own phase by up to 0.8 m, so
/// every step starts and ends overlaps; the motion repeats every `PERIOD` steps.
pub(super) fn swinging_box(i: u32, step: u32) -> Aabb {
    const PERIOD: f32 = 60.0;
    let cell = Vec3::new((i % 20) as f32, ((i / 20) % 10) as f32, (i / 200) as f32) * 1.5;
    let phase = std::f32::consts::TAU * (step as f32 / PERIOD) + i as f32;
    let swing = Vec3::new(phase.sin(), (1.3 * phase).cos(), (0.7 * phase).sin()) * 0.8;
    Aabb::from_center_half_extents(cell + swing, Vec3::splat(0.5))
}

/// Steps 2,000 swinging boxes in `bp` (`at(i, step)`) for 600 steps, then counts the
/// allocations of 120 more; returns them and the pair changes of those 120 steps.
pub(super) fn steady_state_allocations(
    bp: &mut impl BroadPhase,
    at: impl Fn(u32, u32) -> Aabb,
) -> (u64, usize) {
    let bodies: Vec<(ProxyId, Aabb, BodyKind)> = (0..2000)
        .map(|i| (i, at(i, 0), BodyKind::Dynamic))
        .collect();
    bp.insert_bulk(&bodies).expect("valid boxes");
    bp.commit();
    let step = |n: u32, bp: &mut dyn BroadPhase| {
        for i in 0..2000 {
            bp.update(i, at(i, n)).expect("a known body");
        }
        bp.commit();
    };
    // Ten periods grow every buffer to what the motion needs (the motion repeats only up to
    // rounding, so a buffer may still reach a new high in the first periods).
    for n in 1..=600 {
        step(n, bp);
    }
    let before = allocations();
    let mut churn = 0;
    for n in 601..=720 {
        step(n, bp);
        churn += bp.added().len() + bp.removed().len();
    }
    (allocations() - before, churn)
}

#[test]
fn the_incremental_sap_makes_0_allocations_per_step_once_its_buffers_have_grown() {
    let mut sap = IncrementalSap::<AxisTests>::new();
    let (made, churn) = steady_state_allocations(&mut sap, swinging_box);
    assert!(
        churn > 1000,
        "the scene must start and end overlaps: {churn}"
    );
    assert_eq!(made, 0, "{made} allocations in 120 steady steps");
}
