//! The section's text: tables and conclusions.

use super::*;
use crate::markdown::{Section, Table, image, percent, sig};

pub(super) fn section(results: &[ShotResult], balls: usize) -> Section {
    let mut body = format!(
        "{balls} balls of radius {RADIUS} m per run, shot along +x at a static `Collider::cuboid` \
         wall through `UrtoPlugins` (dt = 1/60 s, no gravity, restitution 0.5). Cells: measured \
         fraction through (band model's prediction in brackets). Start offsets follow a \
         golden-ratio sequence over one step's travel, so every crossing phase is sampled. The \
         substep columns switch urto's automatic continuous collision off; the CCD column marks \
         every ball `Ccd` (one substep): each ball's motion is swept against the wall and stops \
         at the first impact.\n\n\
         Band model: the contact stops a ball only if a substep ends with the ball's centre \
         within t/2 + r before the wall's mid-plane (t the wall's thickness, r the radius; past \
         the mid-plane the nearest face is the far one, and the ball is pushed on through), so \
         with n substeps the fraction through is max(0, 1 − (t/2 + r) / (v·dt/n)).\n\n"
    );
    body.push_str(&pass_table(results).to_markdown());
    body.push('\n');
    body.push_str(&image("pass-through against substeps", "tunnelling.svg"));
    body.push_str("Wall time per step of the whole scene (mean over the shots above):\n\n");
    body.push_str(&cost_table(results).to_markdown());
    Section {
        title: "Tunnelling: substeps (and continuous collision)".into(),
        body,
        conclusions: conclusions(results),
    }
}

pub(super) fn pass_table(results: &[ShotResult]) -> Table {
    let mut header = vec!["wall".to_string(), "speed".into(), "travel per step".into()];
    header.extend(
        SUBSTEPS
            .iter()
            .map(|n| format!("{n} substep{}", if *n == 1 { "" } else { "s" })),
    );
    header.push("CCD".into());
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = Table::new(&header);
    for r in results {
        let mut row = vec![
            wall_label(r.shot.thickness),
            r.shot.label(),
            format!("{} m", sig((r.shot.speed * DT) as f64)),
        ];
        for (n, run) in SUBSTEPS.iter().zip(&r.substeps) {
            row.push(format!(
                "{} ({})",
                percent(run.pass_fraction()),
                percent(r.shot.model_pass(*n))
            ));
        }
        row.push(
            r.ccd
                .map_or("pending".into(), |c| percent(c.pass_fraction())),
        );
        t.row(row);
    }
    t
}

pub(super) fn cost_table(results: &[ShotResult]) -> Table {
    let mean = mean_cost(results);
    let balls = results[0].substeps[0].balls as f64;
    let mut t = Table::new(&[
        "setting",
        "µs per step",
        "ns per ball per step",
        "vs 1 substep",
    ]);
    for &(n, us) in &mean {
        t.row(vec![
            format!("{n} substep{}", if n == 1.0 { "" } else { "s" }),
            sig(us),
            sig(us * 1e3 / balls),
            format!("{:.2}×", us / mean[0].1),
        ]);
    }
    let ccd: Vec<f64> = results
        .iter()
        .filter_map(|r| r.ccd.map(|c| c.us_per_step))
        .collect();
    if ccd.len() == results.len() {
        let us = ccd.iter().sum::<f64>() / ccd.len() as f64;
        t.row(vec![
            "CCD, 1 substep".into(),
            sig(us),
            sig(us * 1e3 / balls),
            format!("{:.2}×", us / mean[0].1),
        ]);
    } else {
        t.row(vec![
            "CCD, 1 substep".into(),
            "pending".into(),
            "pending".into(),
            "pending".into(),
        ]);
    }
    t
}

/// Fewest substeps with no ball through, if any run had none.
pub(super) fn measured_substeps(r: &ShotResult) -> Option<u32> {
    SUBSTEPS
        .iter()
        .zip(&r.substeps)
        .find(|(_, run)| run.passed == 0)
        .map(|(n, _)| *n)
}

pub(super) fn conclusions(results: &[ShotResult]) -> Vec<String> {
    let agree = results
        .iter()
        .filter(|r| {
            let model = r.shot.model_substeps();
            measured_substeps(r) == SUBSTEPS.contains(&model).then_some(model)
        })
        .count();
    let mean = mean_cost(results);
    let last = mean[mean.len() - 1];
    let growth = if last.1 / mean[0].1 >= 0.7 * last.0 {
        "almost linearly"
    } else {
        "less than linearly (per-step work is shared)"
    };
    let mut out = vec![format!(
        "substeps stop tunnelling once a substep's travel is below half the wall plus the ball \
         radius, n ≥ v·dt / (t/2 + r); the band model predicts the fewest sufficient substeps (as \
         a power of two ≤ 32, or none) in {agree} of {} shots.",
        results.len()
    )];
    out.push(format!(
        "substeps cost time {growth}: {} substeps cost {:.1}× one per step; a bullet at \
         300 m/s needs v·dt/(t/2 + r) = {:.0} substeps against the 1 cm wall.",
        last.0,
        last.1 / mean[0].1,
        (300.0 * DT / (THICKNESSES[0] / 2.0 + RADIUS)).ceil()
    ));
    let leaky: Vec<String> = results
        .iter()
        .filter(|r| measured_substeps(r).is_none())
        .map(|r| format!("{} at {}", wall_label(r.shot.thickness), r.shot.label()))
        .collect();
    if !leaky.is_empty() {
        out.push(format!(
            "even 32 substeps let balls through for: {} — the case for continuous collision{}.",
            leaky.join(", "),
            if results.iter().any(|r| r.ccd.is_none()) {
                " (CCD row pending)"
            } else {
                ""
            }
        ));
    }
    let ccd: Vec<&TunnelRun> = results.iter().filter_map(|r| r.ccd.as_ref()).collect();
    if !ccd.is_empty() {
        let through: usize = ccd.iter().map(|c| c.passed).sum();
        let total: usize = ccd.iter().map(|c| c.balls).sum();
        let ccd_cost = ccd.iter().map(|c| c.us_per_step).sum::<f64>() / ccd.len() as f64;
        out.push(format!(
            "continuous collision lets {through} of {total} balls through over the {} shots, \
             at {:.2}× the cost of one substep per step, {:.1}× cheaper than {} substeps.",
            ccd.len(),
            ccd_cost / mean[0].1,
            last.1 / ccd_cost,
            last.0
        ));
    }
    out
}
