//! What the numbers say: observed orders, the Pareto front, the cheapest setting per error target.

use super::*;
use urto::dynamics::Integrator;

/// The observed order: the least-squares slope of `log(error)` against `log(dt)` over the
/// longest run of halvings in which the error shrinks by [`MIN_SHRINK`] or more while staying
/// below [`FIT_MAX`] and [`ROUNDING_MARGIN`] times above `problem`'s rounding estimate. `None`
/// when no two points qualify (a method exact on the problem, whose error is rounding alone).
pub(super) fn observed_order(points: &[(f64, f64)], problem: Problem) -> Option<f64> {
    let mut sorted: Vec<(f64, f64)> = points.to_vec();
    sorted.sort_by(|a, b| b.0.total_cmp(&a.0));
    let usable =
        |(dt, e): (f64, f64)| e <= FIT_MAX && e >= ROUNDING_MARGIN * problem.rounding_floor(dt);
    let mut best: &[(f64, f64)] = &[];
    let mut start = 0;
    for end in 1..=sorted.len() {
        let run_continues = end < sorted.len()
            && usable(sorted[end])
            && usable(sorted[end - 1])
            && sorted[end].1 * MIN_SHRINK <= sorted[end - 1].1;
        if !run_continues {
            if end - start > best.len() {
                best = &sorted[start..end];
            }
            start = end;
        }
    }
    (best.len() >= 2).then(|| slope(best))
}

/// Least-squares slope of `ln(error)` against `ln(dt)`.
pub(super) fn slope(points: &[(f64, f64)]) -> f64 {
    let fit: Vec<(f64, f64)> = points.iter().map(|(dt, e)| (dt.ln(), e.ln())).collect();
    let n = fit.len() as f64;
    let (mx, my) = fit
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxy: f64 = fit.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = fit.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

/// The Pareto front over every (method, dt): points no other point beats in both time and error.
pub(super) fn pareto_front(results: &[MethodResult]) -> Vec<(f64, f64, Integrator, f64)> {
    let mut all: Vec<(f64, f64, Integrator, f64)> = results
        .iter()
        .flat_map(|r| {
            r.pareto_points()
                .into_iter()
                .zip(&r.spring)
                .map(move |((cost, err), (dt, _))| (cost, err, r.method, *dt))
        })
        .filter(|(c, e, _, _)| c.is_finite() && e.is_finite())
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64, Integrator, f64)> = Vec::new();
    for p in all {
        if front.last().is_none_or(|last| p.1 < last.1) {
            front.push(p);
        }
    }
    front
}

/// Largest relative energy error over a slice of the drift samples.
pub(super) fn max_error(samples: &[(f64, f64)]) -> f64 {
    samples.iter().map(|s| s.1).fold(0.0, f64::max)
}

/// The cheapest (method, dt) whose spring error is at most `target`.
pub(super) fn cheapest(
    results: &[MethodResult],
    target: f64,
) -> Option<(Integrator, f64, f64, f64)> {
    results
        .iter()
        .flat_map(|r| {
            r.spring
                .iter()
                .map(move |&(dt, err)| (r.method, dt, r.ns_spring / dt, err))
        })
        .filter(|c| c.3 <= target)
        .min_by(|a, b| a.2.total_cmp(&b.2))
}
