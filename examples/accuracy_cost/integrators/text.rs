//! The section's text: tables, notes and conclusions.

use super::analysis::*;
use super::problems::*;
use super::*;
use crate::markdown::{Section, Table, image, sig};
use urto::dynamics::Integrator;

pub(super) fn section(results: &[MethodResult], sz: &Sizes) -> Section {
    let mut body = String::new();
    body.push_str(&format!(
        "Projectile `p = v0 t + g t²/2` (v0 = {LAUNCH}, g = 9.8 m/s², t_end = {PROJECTILE_T_END} s) and an \
         undamped spring through `ForceModel` (k = 1 N/m, m = 1 kg, ω = 1 rad/s, amplitude 1 m, \
         t_end = {SPRING_T_END} s; error in phase space, sqrt(dx² + (dv/ω)²), so amplitude and \
         phase errors both count), f32 state, `dt = 2^-k` for k in {:?}. The observed order is \
         the least-squares slope of log error against log dt over the longest run of halvings \
         that shrink the error at least {MIN_SHRINK}×, with errors below {FIT_MAX:.0e} (above: \
         not yet asymptotic) and at least {ROUNDING_MARGIN}× a pessimistic f32 rounding estimate \
         (half an ulp of the largest coordinate per step, the dashed line; below it the error no \
         longer follows dt). Velocity Verlet and RK4 integrate constant acceleration exactly, so \
         on the projectile they show rounding only, growing with the number of steps.\n\n",
        sz.log2_inv_dt
    ));
    body.push_str(&accuracy_table(results).to_markdown());
    body.push('\n');
    body.push_str(&image("error against dt", "integrators_convergence.svg"));
    body.push_str(&format!(
        "Energy over {} steps of dt = {DRIFT_DT} s of the same spring ({} s, about {:.0} periods); \
         the plot shows the largest error in each period of the oscillation:\n\n",
        sz.drift_steps,
        sz.drift_steps as f32 * DRIFT_DT,
        sz.drift_steps as f64 * DRIFT_DT as f64 / std::f64::consts::TAU
    ));
    body.push_str(&drift_table(results, sz).to_markdown());
    body.push('\n');
    body.push_str(&image("energy drift", "integrators_energy_drift.svg"));
    body.push_str(&format!(
        "Wall time of one `integrate` call over {} bodies, per body (one thread):\n\n",
        sz.bodies
    ));
    body.push_str(&cost_table(results).to_markdown());
    body.push('\n');
    body.push_str(&noise_note(results));
    body.push_str(
        "Pareto plot: each point is one (method, dt); x is the wall time to simulate one second \
         of the spring per body (time per step / dt), y the error at t_end. The dashed line joins \
         the points no other point beats in both.\n\n",
    );
    body.push_str(&image("Pareto plot", "integrators_pareto.svg"));
    body.push_str(&front_table(results).to_markdown());
    Section {
        title: "Integrators × dt".into(),
        body,
        conclusions: conclusions(results),
    }
}

pub(super) fn order_cell(points: &[(f64, f64)], problem: Problem) -> String {
    match observed_order(points, problem) {
        Some(s) => format!("{s:.2}"),
        None => "— (exact: rounding only)".into(),
    }
}

pub(super) fn accuracy_table(results: &[MethodResult]) -> Table {
    let mut t = Table::new(&[
        "integrator",
        "order (theory)",
        "observed order, projectile",
        "observed order, spring",
        "projectile error at dt = 1/60 (m)",
        "spring error at dt = 1/60 (m)",
    ]);
    for r in results {
        t.row(vec![
            r.method.name().into(),
            r.method.order().to_string(),
            order_cell(&r.projectile, PROJECTILE),
            order_cell(&r.spring, SPRING),
            sig(projectile_error(r.method, GAME_DT)),
            sig(spring_error(r.method, GAME_DT)),
        ]);
    }
    t
}

/// Theory for the drift where it is a closed form: explicit Euler multiplies the energy of
/// `x'' = -ω²x` by `1 + (ω dt)²` per step; RK4 by `1 - (ω dt)^6/72` (to leading order). A
/// measurement far above the theory is f32 rounding, and the cell says so.
pub(super) fn drift_theory(method: Integrator, steps: usize, measured: f64) -> String {
    let h2 = (DRIFT_DT as f64).powi(2);
    let theory = match method {
        Integrator::ExplicitEuler => (1.0 + h2).powi(steps as i32) - 1.0,
        Integrator::Rk4 => 1.0 - (1.0 - h2 * h2 * h2 / 72.0).powi(steps as i32),
        _ => return "bounded (symplectic)".into(),
    };
    if measured > 100.0 * theory {
        format!("{} (measured: f32 rounding)", sig(theory))
    } else {
        sig(theory)
    }
}

pub(super) fn drift_table(results: &[MethodResult], sz: &Sizes) -> Table {
    let mut t = Table::new(&[
        "integrator",
        "max abs(E/E0 − 1)",
        "at the end (last period)",
        "theory at the end",
        "max in last tenth / max in first tenth",
    ]);
    for r in results {
        let tenth = (r.drift.len() / 10).max(1);
        let first = max_error(&r.drift[..tenth]);
        let last = max_error(&r.drift[r.drift.len() - tenth..]);
        let end = r.drift.last().map_or(f64::NAN, |s| s.1);
        t.row(vec![
            r.method.name().into(),
            sig(max_error(&r.drift)),
            sig(end),
            drift_theory(r.method, sz.drift_steps, end),
            sig(last / first),
        ]);
    }
    t
}

pub(super) fn cost_table(results: &[MethodResult]) -> Table {
    let base = results[0].ns_spring;
    let mut t = Table::new(&[
        "integrator",
        "field evaluations / step",
        "ns / body / step, gravity only",
        "ns / body / step, spring per body",
        "spring cost vs explicit Euler",
    ]);
    for r in results {
        t.row(vec![
            r.method.name().into(),
            r.method.evaluations_per_step().to_string(),
            sig(r.ns_gravity),
            sig(r.ns_spring),
            format!("{:.2}×", r.ns_spring / base),
        ]);
    }
    t
}

/// Explicit and symplectic Euler do the same work in a different order, so the gap between their
/// times gauges this run's timing noise.
pub(super) fn noise_note(results: &[MethodResult]) -> String {
    let by = |m: Integrator| results.iter().find(|r| r.method == m);
    let (Some(a), Some(b)) = (
        by(Integrator::ExplicitEuler),
        by(Integrator::SymplecticEuler),
    ) else {
        return String::new();
    };
    let gap = |x: f64, y: f64| 100.0 * (x / y - 1.0).abs();
    format!(
        "Explicit and symplectic Euler do identical work in a different order, so their gap \
         ({:.0} % with gravity, {:.0} % with springs) gauges the timing noise of this run; smaller \
         differences between methods are not significant.\n\n",
        gap(a.ns_gravity, b.ns_gravity),
        gap(a.ns_spring, b.ns_spring)
    )
}

pub(super) fn front_table(results: &[MethodResult]) -> Table {
    let mut t = Table::new(&[
        "spring error target (m)",
        "cheapest setting",
        "its error (m)",
        "ns per body per simulated second",
    ]);
    for target in TARGETS {
        match cheapest(results, target) {
            Some((m, dt, cost, err)) => t.row(vec![
                format!("{target:.0e}"),
                format!("{}, dt = 2^{}", m.name(), dt.log2().round()),
                sig(err),
                sig(cost),
            ]),
            None => t.row(vec![
                format!("{target:.0e}"),
                "none reaches it in f32".into(),
                "—".into(),
                "—".into(),
            ]),
        }
    }
    t
}

pub(super) fn conclusions(results: &[MethodResult]) -> Vec<String> {
    let mut out = Vec::new();
    let by = |m: Integrator| results.iter().find(|r| r.method == m);
    if let (Some(ee), Some(se)) = (
        by(Integrator::ExplicitEuler),
        by(Integrator::SymplecticEuler),
    ) {
        let (se_drift, ee_drift) = (max_error(&se.drift), max_error(&ee.drift));
        out.push(format!(
            "symplectic Euler does exactly the work of explicit Euler (one field evaluation, the \
             same updates in another order; measured {:.2}× here, which gauges the timing noise) \
             and keeps the energy error at most {} over the long run, where explicit Euler's \
             reaches {}{}",
            se.ns_spring / ee.ns_spring,
            sig(se_drift),
            sig(ee_drift),
            if ee_drift > 10.0 * se_drift {
                ": free accuracy; keep explicit Euler only to reproduce the slides."
            } else {
                "."
            }
        ));
    }
    let at_60: Vec<String> = results
        .iter()
        .map(|r| {
            format!(
                "{} {} m at {:.1}× the cost",
                r.method.name(),
                sig(spring_error(r.method, GAME_DT)),
                r.ns_spring / results[0].ns_spring
            )
        })
        .collect();
    out.push(format!(
        "at the game's dt = 1/60 the spring's error at t = 8 s is: {} (cost relative to explicit \
         Euler).",
        at_60.join(", ")
    ));
    for target in TARGETS {
        if let Some((m, dt, cost, _)) = cheapest(results, target) {
            out.push(format!(
                "for a spring error ≤ {target:.0e} m at t = 8 s the cheapest setting measured is {} at \
                 dt = 2^{} s ({} ns per body per simulated second).",
                m.name(),
                dt.log2().round(),
                sig(cost)
            ));
        }
    }
    out
}
