//! The section's plots and its series in the rerun recording.

use super::*;
use crate::Context;
use crate::plot::{Axis, Chart, Series, Style, save_svg};
use crate::recording::{Time, slug};
use plotters::chart::SeriesLabelPosition;
use std::error::Error;

pub(super) fn plot(
    ctx: &Context,
    rows: &[KindRow],
    pairs: &[MeshPair],
) -> Result<(), Box<dyn Error>> {
    let mut model = Chart::new(
        "Cost model check: Nv·Cv + Nn·Cn + Ns·Cs against measured",
        Axis::log("predicted time per query (µs)"),
        Axis::log("measured time per query (µs)"),
    )
    .legend_at(SeriesLabelPosition::UpperLeft);
    let per_kind = |title: &str, y: &str| {
        Chart::new(
            title,
            Axis::categories("bounding volume", &KINDS),
            Axis::log(y),
        )
        .legend_at(SeriesLabelPosition::UpperRight)
    };
    let mut time = per_kind("Query time by BV kind", "measured time per query (µs)");
    let mut tests = per_kind(
        "Tighter BVs: fewer triangle tests Ns...",
        "triangle tests Ns per query",
    );
    let mut bv_cost = per_kind("...for dearer BV tests Cn", "Cn, one BV test (ns)")
        .legend_at(SeriesLabelPosition::LowerRight);
    let x = |r: &KindRow| KINDS.iter().position(|k| *k == r.kind).unwrap_or(0) as f64;
    for p in pairs {
        let of_pair: Vec<&KindRow> = rows.iter().filter(|r| r.pair == p.name).collect();
        let series = |f: fn(&KindRow) -> f64| of_pair.iter().map(move |r| (x(r), f(r)));
        let check = of_pair.iter().map(|r| (r.predicted_us, r.measured_us));
        model = model.with(Series::new(&p.name, Style::Points, check));
        time = time.with(Series::new(
            &p.name,
            Style::LinePoints,
            series(|r| r.measured_us),
        ));
        tests = tests.with(Series::new(
            &p.name,
            Style::LinePoints,
            series(|r| r.stats[2]),
        ));
        bv_cost = bv_cost.with(Series::new(
            &p.name,
            Style::LinePoints,
            series(|r| r.costs[1]),
        ));
        for r in &of_pair {
            model
                .labels
                .push((r.predicted_us, r.measured_us, format!("  {}", r.kind)));
        }
    }
    let all = rows.iter().flat_map(|r| [r.predicted_us, r.measured_us]);
    let (lo, hi) = all.fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(v), h.max(v)));
    model = model.with(Series::new("y = x", Style::Reference, [(lo, lo), (hi, hi)]));
    save_svg(
        &ctx.out.join("bounding_volumes.svg"),
        &[model, time, tests, bv_cost],
        2,
    )
}

pub(super) fn record(ctx: &Context, rows: &[KindRow], pairs: &[MeshPair]) {
    for p in pairs {
        let of_pair: Vec<(usize, &KindRow)> = rows
            .iter()
            .filter(|r| r.pair == p.name)
            .enumerate()
            .collect();
        let base = format!("bounding_volumes/{}", slug(&p.name));
        let at = |i: usize| Time::Sequence(i as i64);
        for field in 0..KindRow::FIELDS {
            let name = of_pair
                .first()
                .map_or("", |(_, r)| r.named_values()[field].0);
            let values = of_pair
                .iter()
                .map(|(i, r)| (at(*i), r.named_values()[field].1));
            ctx.rec.series("bv_kind", &format!("{base}/{name}"), values);
        }
    }
}
