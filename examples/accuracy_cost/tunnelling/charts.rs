//! The section's plots and its series in the rerun recording.

use super::*;
use crate::Context;
use crate::plot::{Axis, Chart, Series, Style, save_svg};
use crate::recording::{Time, slug};
use plotters::chart::SeriesLabelPosition;
use std::error::Error;

pub(super) fn plot(ctx: &Context, results: &[ShotResult]) -> Result<(), Box<dyn Error>> {
    let mut charts = Vec::new();
    for thickness in THICKNESSES {
        let mut chart = Chart::new(
            format!(
                "Pass-through, {}, ball r = {RADIUS} m, dt = 1/60 s",
                wall_label(thickness)
            ),
            Axis::log("substeps per step"),
            Axis::linear("fraction through the wall"),
        )
        .y_range(-0.02, 1.02)
        .legend_at(SeriesLabelPosition::UpperRight);
        let shots = results.iter().filter(|r| r.shot.thickness == thickness);
        for (i, r) in shots.enumerate() {
            let pts = SUBSTEPS
                .iter()
                .zip(&r.substeps)
                .map(|(n, run)| (*n as f64, run.pass_fraction()));
            chart = chart.with(Series::new(r.shot.label(), Style::LinePoints, pts));
            let model = SUBSTEPS.iter().map(|&n| (n as f64, r.shot.model_pass(n)));
            let name = if i == 0 { "band model" } else { "" };
            chart = chart.with(Series::new(name, Style::Reference, model));
            if let Some(c) = r.ccd {
                chart = chart.with(Series::new(
                    format!("{} with CCD", r.shot.label()),
                    Style::Points,
                    [(1.0, c.pass_fraction())],
                ));
            }
        }
        charts.push(chart);
    }
    charts.push(collapse_chart(results));
    let mean = mean_cost(results);
    let linear = mean.iter().map(|&(n, _)| (n, mean[0].1 * n));
    charts.push(
        Chart::new(
            format!(
                "Cost of substeps ({} balls + wall)",
                results[0].substeps[0].balls
            ),
            Axis::log("substeps per step"),
            Axis::log("wall time per step (µs)"),
        )
        .with(Series::new(
            "measured (mean over shots)",
            Style::LinePoints,
            mean.clone(),
        ))
        .with(Series::new("1 substep × n", Style::Reference, linear)),
    );
    save_svg(&ctx.out.join("tunnelling.svg"), &charts, 2)?;
    Ok(())
}

/// Every run against the one number the band model says matters, substep travel over band
/// width: all shots should fall on `max(0, 1 - band/travel)`.
pub(super) fn collapse_chart(results: &[ShotResult]) -> Chart {
    let mut chart = Chart::new(
        "All runs against the band model",
        Axis::log("substep travel / (t/2 + r)"),
        Axis::linear("fraction through the wall"),
    )
    .y_range(-0.02, 1.02)
    .legend_at(SeriesLabelPosition::UpperLeft);
    let ratio = |shot: Shot, n: u32| (shot.speed * DT / n as f32 / shot.band()) as f64;
    for thickness in THICKNESSES {
        let pts = results
            .iter()
            .filter(|r| r.shot.thickness == thickness)
            .flat_map(|r| {
                SUBSTEPS
                    .iter()
                    .zip(&r.substeps)
                    .map(|(n, run)| (ratio(r.shot, *n), run.pass_fraction()))
            });
        chart = chart.with(Series::new(wall_label(thickness), Style::Points, pts));
    }
    let all = results
        .iter()
        .flat_map(|r| SUBSTEPS.iter().map(|n| ratio(r.shot, *n)));
    let (lo, hi) = all.fold((f64::INFINITY, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
    let model = (0..=100).map(|i| {
        let x = lo * (hi / lo).powf(i as f64 / 100.0);
        (x, (1.0 - 1.0 / x).max(0.0))
    });
    chart.with(Series::new(
        "model max(0, 1 − band/travel)",
        Style::Reference,
        model,
    ))
}

pub(super) fn record(ctx: &Context, results: &[ShotResult]) {
    for r in results {
        let base = format!(
            "tunnelling/{}/{}",
            slug(&wall_label(r.shot.thickness)),
            slug(&r.shot.label())
        );
        let at = |n: u32| Time::Sequence(n as i64);
        let runs = || SUBSTEPS.iter().zip(&r.substeps);
        ctx.rec.series(
            "substeps",
            &format!("{base}/pass_fraction"),
            runs().map(|(n, x)| (at(*n), x.pass_fraction())),
        );
        ctx.rec.series(
            "substeps",
            &format!("{base}/model_pass_fraction"),
            SUBSTEPS.iter().map(|&n| (at(n), r.shot.model_pass(n))),
        );
        ctx.rec.series(
            "substeps",
            &format!("{base}/us_per_step"),
            runs().map(|(n, x)| (at(*n), x.us_per_step)),
        );
        if let Some(c) = r.ccd {
            ctx.rec.series(
                "substeps",
                &format!("{base}/ccd_pass_fraction"),
                [(at(1), c.pass_fraction())],
            );
            ctx.rec.series(
                "substeps",
                &format!("{base}/ccd_us_per_step"),
                [(at(1), c.us_per_step)],
            );
        }
    }
}
