//! The section's plots and its series in the rerun recording.

use super::*;
use crate::Context;
use crate::plot::{Axis, Chart, Series, Style, save_svg};
use crate::recording::{Time, slug};
use plotters::chart::SeriesLabelPosition;
use std::error::Error;

pub(super) fn plot(
    ctx: &Context,
    runs: &[BounceRun],
    threshold: f64,
) -> Result<(), Box<dyn Error>> {
    let ks = 1..=BOUNCES;
    let mut heights = Chart::new(
        format!("Apex after bounce k, e = {E}, h0 = {H0} m"),
        Axis::linear("bounce k"),
        Axis::log("apex height of the ball's bottom (m)"),
    )
    .y_range(3e-3, 30.0)
    .legend_at(SeriesLabelPosition::UpperRight);
    let mut ratios = Chart::new(
        "Measured over analytic apex (1 = exact)",
        Axis::linear("bounce k"),
        Axis::log("measured / analytic apex"),
    )
    .y_range(0.03, 100.0)
    .legend_at(SeriesLabelPosition::UpperLeft);
    for (label, r) in distinct_runs(runs) {
        let apex = r
            .apexes
            .iter()
            .take(BOUNCES)
            .enumerate()
            .map(|(i, h)| ((i + 1) as f64, *h));
        heights = heights.with(Series::new(&label, Style::LinePoints, apex));
        let ratio = ks
            .clone()
            .filter_map(|k| r.error(k).map(|e| (k as f64, 1.0 + e)));
        ratios = ratios.with(Series::new(&label, Style::LinePoints, ratio));
    }
    heights = heights.with(Series::new(
        "analytic e^(2k) h0",
        Style::Reference,
        ks.clone().map(|k| (k as f64, analytic(k))),
    ));
    let h_thr = threshold * threshold / (2.0 * G);
    heights = heights.with(Series::new(
        format!(
            "restitution threshold {threshold} m/s ⇒ h = {:.1} cm",
            h_thr * 100.0
        ),
        Style::Reference,
        [(1.0, h_thr), (BOUNCES as f64, h_thr)],
    ));
    ratios = ratios.with(Series::new(
        "exact",
        Style::Reference,
        [(1.0, 1.0), (BOUNCES as f64, 1.0)],
    ));
    save_svg(&ctx.out.join("bounce.svg"), &[heights, ratios], 2)
}

/// The runs to draw, each labelled with every setting that gave the same apexes (drawn once,
/// since identical lines would hide each other).
pub(super) fn distinct_runs(runs: &[BounceRun]) -> Vec<(String, &BounceRun)> {
    let mut out: Vec<(String, &BounceRun)> = Vec::new();
    for r in runs {
        match out.iter_mut().find(|(_, seen)| same_apexes(seen, r)) {
            Some((label, _)) => *label = format!("{label} = {}", r.setting.label()),
            None => out.push((r.setting.label(), r)),
        }
    }
    out
}

pub(super) fn record(ctx: &Context, runs: &[BounceRun]) {
    let at = |k: usize| Time::Sequence(k as i64);
    ctx.rec.series(
        "bounce",
        "bounce/analytic/apex_m",
        (1..=BOUNCES).map(|k| (at(k), analytic(k))),
    );
    for r in runs {
        let base = format!("bounce/{}", slug(&r.setting.label()));
        let apex = r.apexes.iter().enumerate().map(|(i, h)| (at(i + 1), *h));
        ctx.rec.series("bounce", &format!("{base}/apex_m"), apex);
        let err = (1..=BOUNCES).filter_map(|k| r.error(k).map(|e| (at(k), e)));
        ctx.rec
            .series("bounce", &format!("{base}/relative_error"), err);
    }
}
