//! The section's text: the table, checks and conclusions.

use super::*;
use crate::markdown::{Section, Table, image, sig};

pub(super) fn section(rows: &[KindRow], sz: &Sizes) -> Section {
    let mut body = format!(
        "Hierarchies built with binned SAH (leaf size {}) over mesh A; {} seeded placements of B \
         near A per pair; enumerate-all depth-first query with the exact triangle test. Counts \
         and times are per placement; `Cv`, `Cn`, `Cs` (ns) are measured by replaying the work \
         of the {COST_SAMPLES} busiest placements (count-weighted); \"model / measured\" is the \
         cost model's prediction over the measured query time. Every time is the smallest of \
         {REPEATS} repeated means (other processes only add time). Build time is mesh A's \
         hierarchy. {}\n\n",
        urto::bvh::DEFAULT_LEAF_SIZE,
        sz.placements,
        same_pairs_check(rows)
    );
    body.push_str(&table(rows).to_markdown());
    body.push('\n');
    body.push_str(&image(
        "cost model and BV trade-off",
        "bounding_volumes.svg",
    ));
    Section {
        title: "Bounding-volume hierarchies and the cost model".into(),
        body,
        conclusions: conclusions(rows),
    }
}

pub(super) fn table(rows: &[KindRow]) -> Table {
    let mut t = Table::new(&[
        "mesh pair (triangles)",
        "BV",
        "build (ms)",
        "nodes",
        "Nv",
        "Nn",
        "Ns",
        "Cv (ns)",
        "Cn (ns)",
        "Cs (ns)",
        "model (µs)",
        "measured (µs)",
        "model / measured",
        "pairs found",
    ]);
    for r in rows {
        t.row(vec![
            format!("{} ({} × {})", r.pair, r.triangles.0, r.triangles.1),
            r.kind.into(),
            sig(r.build_ms),
            r.nodes.to_string(),
            sig(r.stats[0]),
            sig(r.stats[1]),
            sig(r.stats[2]),
            sig(r.costs[0]),
            sig(r.costs[1]),
            sig(r.costs[2]),
            sig(r.predicted_us),
            sig(r.measured_us),
            format!("{:.2}", r.predicted_us / r.measured_us),
            sig(r.pairs_found),
        ]);
    }
    t
}

/// Whether every BV kind found the same number of intersecting pairs on each mesh pair (the
/// BVs only prune; the leaf test decides).
pub(super) fn same_pairs_check(rows: &[KindRow]) -> String {
    let differing: Vec<&str> = rows
        .iter()
        .filter(|r| {
            rows.iter()
                .any(|o| o.pair == r.pair && o.pairs_found != r.pairs_found)
        })
        .map(|r| r.pair.as_str())
        .collect();
    if differing.is_empty() {
        "Check: all six kinds find the same number of intersecting triangle pairs on every mesh \
         pair (the BVs only prune; the exact test decides)."
            .into()
    } else {
        format!(
            "Warning: the kinds disagree on the pairs found for {}.",
            differing.join(", ")
        )
    }
}

/// The row of `pair` minimising `key`.
pub(super) fn best<'a>(
    rows: &'a [KindRow],
    pair: &str,
    key: impl Fn(&KindRow) -> f64,
) -> Option<&'a KindRow> {
    rows.iter()
        .filter(|r| r.pair == pair)
        .min_by(|a, b| key(a).total_cmp(&key(b)))
}

/// The mesh pairs in table order.
pub(super) fn pairs_of(rows: &[KindRow]) -> Vec<&str> {
    let mut pairs: Vec<&str> = rows.iter().map(|r| r.pair.as_str()).collect();
    pairs.dedup();
    pairs
}

/// The median of some values (the upper one for an even count); NaN for none.
pub(super) fn median(values: impl Iterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

pub(super) fn conclusions(rows: &[KindRow]) -> Vec<String> {
    let mut out = Vec::new();
    for pair in pairs_of(rows) {
        let (Some(q), Some(slow), Some(rebuild)) = (
            best(rows, pair, |r| r.measured_us),
            best(rows, pair, |r| -r.measured_us),
            best(rows, pair, |r| r.build_ms * 1e3 + r.measured_us),
        ) else {
            continue;
        };
        out.push(format!(
            "{pair}: fastest query {} ({} µs, {:.1}× faster than {}); if the hierarchy is rebuilt \
             every query (deforming mesh), {} is cheapest (build + query {} µs).",
            q.kind,
            sig(q.measured_us),
            slow.measured_us / q.measured_us,
            slow.kind,
            rebuild.kind,
            sig(rebuild.build_ms * 1e3 + rebuild.measured_us),
        ));
    }
    let ratio = |r: &KindRow| r.predicted_us / r.measured_us;
    let medians: Vec<String> = pairs_of(rows)
        .iter()
        .map(|p| {
            format!(
                "{p} {:.2}",
                median(rows.iter().filter(|r| r.pair == *p).map(ratio))
            )
        })
        .collect();
    let (lo, hi) = rows
        .iter()
        .map(ratio)
        .fold((f64::INFINITY, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
    out.push(format!(
        "the slides' cost model Nv·Cv + Nn·Cn + Ns·Cs gives {lo:.2}–{hi:.2} times the measured \
         query time (median per pair: {}){}",
        medians.join(", "),
        if lo > 0.5 && hi < 2.0 {
            ": counting visits, BV tests and triangle tests ranks hierarchies before timing \
             them; where the ratio falls below 1, the unit costs timed in isolation miss the \
             cache misses of the real traversal."
        } else {
            ": the counters rank hierarchies, but the unit costs measured in isolation do not \
             add up to the real query time."
        }
    ));
    out
}
