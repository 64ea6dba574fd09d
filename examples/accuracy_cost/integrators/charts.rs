//! The section's plots and its series in the rerun recording.

use super::analysis::*;
use super::*;
use crate::Context;
use crate::plot::{Axis, Chart, Series, Style, save_svg};
use crate::recording::{Time, slug};
use plotters::chart::SeriesLabelPosition;

pub(super) fn plot(
    ctx: &Context,
    results: &[MethodResult],
) -> Result<(), Box<dyn std::error::Error>> {
    let label = |r: &MethodResult, pts: &[(f64, f64)], problem| match observed_order(pts, problem) {
        Some(s) => format!("{} (slope {s:.2})", r.method.name()),
        None => format!("{} (rounding only)", r.method.name()),
    };
    let convergence =
        |title: &str, problem: Problem, pick: fn(&MethodResult) -> &Vec<(f64, f64)>| {
            let chart = Chart::new(title, Axis::log("dt (s)"), Axis::log("error at t_end (m)"))
                .legend_at(SeriesLabelPosition::UpperLeft);
            let chart = results.iter().fold(chart, |c, r| {
                c.with(Series::new(
                    label(r, pick(r), problem),
                    Style::LinePoints,
                    pick(r).clone(),
                ))
            });
            let floor = results[0]
                .spring
                .iter()
                .map(|&(dt, _)| (dt, problem.rounding_floor(dt)));
            chart.with(Series::new(
                "f32 rounding estimate",
                Style::Reference,
                floor,
            ))
        };
    save_svg(
        &ctx.out.join("integrators_convergence.svg"),
        &[
            convergence("Projectile, t_end = 2 s", PROJECTILE, |r| &r.projectile),
            convergence("Spring (ω = 1 rad/s), t_end = 8 s", SPRING, |r| &r.spring),
        ],
        2,
    )?;
    let drift = results.iter().fold(
        Chart::new(
            format!(
                "Energy drift of the spring, dt = {DRIFT_DT} s (ω·dt = {DRIFT_DT}), maxima per period"
            ),
            Axis::linear("simulated time (s)"),
            Axis::log("|E / E0 − 1|"),
        )
        .legend_at(SeriesLabelPosition::UpperLeft),
        |c, r| c.with(Series::new(r.method.name(), Style::Line, r.drift.clone())),
    );
    save_svg(&ctx.out.join("integrators_energy_drift.svg"), &[drift], 1)?;
    let front: Vec<(f64, f64)> = pareto_front(results).iter().map(|p| (p.0, p.1)).collect();
    let pareto = results
        .iter()
        .fold(
            Chart::new(
                "Spring error against cost (points: dt = 2^-k)",
                Axis::log("wall time per body per simulated second (ns)"),
                Axis::log("error at t_end = 8 s (m)"),
            )
            .legend_at(SeriesLabelPosition::UpperRight),
            |c, r| {
                c.with(Series::new(
                    r.method.name(),
                    Style::LinePoints,
                    r.pareto_points(),
                ))
            },
        )
        .with(Series::new("Pareto front", Style::Reference, front));
    save_svg(&ctx.out.join("integrators_pareto.svg"), &[pareto], 1)?;
    Ok(())
}

pub(super) fn record(ctx: &Context, results: &[MethodResult]) {
    let k = |dt: f64| Time::Sequence((-dt.log2()).round() as i64);
    for r in results {
        let name = slug(r.method.name());
        for (what, pts) in [("projectile", &r.projectile), ("spring", &r.spring)] {
            let series = pts.iter().map(|&(dt, e)| (k(dt), e.log10()));
            ctx.rec.series(
                "log2_inv_dt",
                &format!("integrators/convergence/{what}/{name}/log10_error"),
                series,
            );
        }
        let drift = r.drift.iter().map(|&(t, e)| (Time::Seconds(t), e.log10()));
        ctx.rec.series(
            "sim_time",
            &format!("integrators/energy_drift/{name}/log10_rel_error"),
            drift,
        );
        let pareto = r.pareto_points();
        let cost = pareto
            .iter()
            .zip(&r.spring)
            .map(|(p, (dt, _))| (k(*dt), p.0.log10()));
        ctx.rec.series(
            "log2_inv_dt",
            &format!("integrators/pareto/{name}/log10_ns_per_sim_second"),
            cost,
        );
    }
    for (i, r) in results.iter().enumerate() {
        let at = Time::Sequence(i as i64);
        ctx.rec.series(
            "integrator",
            "integrators/ns_per_body_step/gravity",
            [(at, r.ns_gravity)],
        );
        ctx.rec.series(
            "integrator",
            "integrators/ns_per_body_step/spring",
            [(at, r.ns_spring)],
        );
    }
}
