//! The section's text: the table and conclusions.

use super::*;
use crate::markdown::{Section, Table, image, sig};
use urto::prelude::*;

pub(super) fn section(runs: &[BounceRun], threshold: f64) -> Section {
    let allowed = bounces_allowed(threshold);
    let mut body = format!(
        "A ball (r = {RADIUS} m) dropped from h0 = {H0} m (its bottom above the plane) onto a \
         static half-space through `UrtoPlugins` with gravity 9.8 m/s², restitution {E} on both \
         bodies, {DURATION} s simulated. Apexes are the highest sampled height where the vertical \
         velocity turns down (within g·dt²/8 of the sampled trajectory's true top). Cells: \
         relative error of apex k against e^(2k) h0; \"—\": no such bounce.\n\n\
         The solver's `restitution_threshold` ({threshold} m/s) gives e = 0 to slower approaches, \
         so a bounce from an apex below {:.1} cm does not happen: with these numbers the analytic \
         sequence with the threshold has {allowed} bounces, and later columns are empty by design, \
         not by error.\n\n",
        threshold * threshold / (2.0 * G) * 100.0
    );
    body.push_str(&table(runs).to_markdown());
    body.push('\n');
    body.push_str(&image("apex heights", "bounce.svg"));
    Section {
        title: "Bounce accuracy".into(),
        body,
        conclusions: conclusions(runs, allowed),
    }
}

pub(super) fn table(runs: &[BounceRun]) -> Table {
    let mut header = vec![
        "setting".to_string(),
        "bounces seen".into(),
        "µs / step".into(),
    ];
    header.extend((1..=BOUNCES).map(|k| format!("k = {k}")));
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = Table::new(&header);
    let mut analytic_row = vec!["analytic h_k (m)".to_string(), "—".into(), "—".into()];
    analytic_row.extend((1..=BOUNCES).map(|k| sig(analytic(k))));
    t.row(analytic_row);
    for r in runs {
        let mut row = vec![
            r.setting.label(),
            r.apexes.len().to_string(),
            sig(r.us_per_step),
        ];
        row.extend((1..=BOUNCES).map(|k| {
            r.error(k)
                .map_or("—".into(), |e| format!("{:+.1} %", 100.0 * e))
        }));
        t.row(row);
    }
    t
}

pub(super) fn conclusions(runs: &[BounceRun], allowed: usize) -> Vec<String> {
    let n = allowed.min(6);
    let mut ranked: Vec<&BounceRun> = runs.iter().collect();
    ranked.sort_by(|a, b| a.mean_error(n).total_cmp(&b.mean_error(n)));
    let list: Vec<String> = ranked
        .iter()
        .map(|r| format!("{} {:.1} %", r.setting.label(), 100.0 * r.mean_error(n)))
        .collect();
    let mut out = vec![format!(
        "mean |apex error| over bounces 1–{n}, best first: {}.",
        list.join("; ")
    )];
    let by = |dt: f32, sub: u32, m: Integrator| {
        runs.iter()
            .filter(|r| !r.setting.soft_step)
            .find(|r| r.setting.dt == dt && r.setting.substeps == sub && r.setting.integrator == m)
    };
    let default = by(1.0 / 60.0, 1, Integrator::SymplecticEuler);
    let fine = by(1.0 / 240.0, 1, Integrator::SymplecticEuler);
    let sub = by(1.0 / 60.0, 4, Integrator::SymplecticEuler);
    if let (Some(d), Some(f), Some(s)) = (default, fine, sub) {
        let (best, worst) = integrator_extremes(runs, n);
        out.push(format!(
            "a 4× finer contact step divides the error of the default (symplectic Euler, 1/60) by \
             {:.1} with 4 substeps ({:.1}× the time per step) and by {:.1} with dt = 1/240 (4× the \
             steps); at dt = 1/60 the integrator alone moves it from {} ({:.1} %) to {} ({:.1} %).",
            d.mean_error(n) / s.mean_error(n),
            s.us_per_step / d.us_per_step,
            d.mean_error(n) / f.mean_error(n),
            best.setting.integrator.name(),
            100.0 * best.mean_error(n),
            worst.setting.integrator.name(),
            100.0 * worst.mean_error(n),
        ));
    }
    if let (Some(d), Some(soft)) = (default, runs.iter().find(|r| r.setting.soft_step)) {
        out.push(format!(
            "the rigid-body solver (`SoftStepPlugin`: contacts found ahead of the impact, 4 \
             solver substeps) misses by {:.1} % at dt = 1/60 against the legacy response's \
             {:.1} %, for {:.1}× its time per step. Its first apex is off by {:+.1} % but the \
             {n}th by {:+.1} %: the substeps integrate each flight with symplectic Euler, which \
             loses about `v h / 2` of height per flight (h = dt / 4), relatively more on the \
             lower, slower bounces, and the losses compound from bounce to bounce.",
            100.0 * soft.mean_error(n),
            100.0 * d.mean_error(n),
            soft.us_per_step / d.us_per_step,
            100.0 * soft.error(1).unwrap_or(f64::NAN),
            100.0 * soft.error(n).unwrap_or(f64::NAN),
        ));
    }
    out.extend(identical_runs(runs));
    let early: Vec<String> = runs
        .iter()
        .filter(|r| r.apexes.len() < allowed)
        .map(|r| format!("{} ({})", r.setting.label(), r.apexes.len()))
        .collect();
    if !early.is_empty() {
        out.push(format!(
            "the restitution threshold ends the sequence after {allowed} bounces analytically; \
             settings that lose height reach it sooner: {}.",
            early.join(", ")
        ));
    }
    out
}

/// Pairs of runs with the same apexes, with the reason when it is known.
pub(super) fn identical_runs(runs: &[BounceRun]) -> Vec<String> {
    let exact_on_gravity = |r: &BounceRun| {
        matches!(
            r.setting.integrator,
            Integrator::VelocityVerlet | Integrator::Rk4
        )
    };
    let mut out = Vec::new();
    for (i, a) in runs.iter().enumerate() {
        for b in runs[i + 1..].iter().filter(|b| same_apexes(a, b)) {
            let why = if exact_on_gravity(a) && exact_on_gravity(b) && a.setting.dt == b.setting.dt
            {
                ": both integrate constant gravity exactly, so what error remains comes from the \
                 contact"
            } else {
                ""
            };
            out.push(format!(
                "{} and {} give the same apexes within {} %{why}.",
                a.setting.label(),
                b.setting.label(),
                100.0 * SAME_APEX
            ));
        }
    }
    out
}

/// The best and worst of the dt = 1/60, one-substep runs (the integrators alone).
pub(super) fn integrator_extremes(runs: &[BounceRun], n: usize) -> (&BounceRun, &BounceRun) {
    let same_step = || {
        runs.iter()
            .filter(|r| r.setting.dt == 1.0 / 60.0 && r.setting.substeps == 1)
            .filter(|r| !r.setting.soft_step)
    };
    let key = |a: &&BounceRun, b: &&BounceRun| a.mean_error(n).total_cmp(&b.mean_error(n));
    // SETTINGS holds several dt = 1/60 one-substep runs, so both exist.
    (
        same_step().min_by(key).unwrap_or(&runs[0]),
        same_step().max_by(key).unwrap_or(&runs[0]),
    )
}
