//! The section's text: the table and what it shows.

use super::*;
use crate::markdown::{Section, Table, sig};

pub(super) fn section(runs: &[StackRun], seconds: f32) -> Section {
    let mut body = format!(
        "A stack of {BOXES} unit boxes (1 kg, friction 0.6) standing on a half-space through \
         `UrtoPlugins` with `SoftStepPlugin`, dt = 1/60 s, {seconds} s simulated, for each \
         number of solver substeps and of relax passes per substep (the other settings are the \
         defaults). Drift (the sway): the farthest any box got, over the rest of the run, from where it rested after the first second. \
         Penetration: the deepest overlap of two neighbours (or of the bottom box with the \
         ground) over the run. Sag: the top box's drop at the end (the soft contacts' give \
         under the stack's weight, `load / (m_eff ω²)`, plus any collapse). \
         Contact passes: substeps × (1 solve + relax passes), the solver's work. µs / step: wall \
         time of the whole physics step (noisy: the machine is shared).\n\n"
    );
    body.push_str(&table(runs).to_markdown());
    body.push('\n');
    Section {
        title: "The rigid-body solver: substeps and relax passes".into(),
        body,
        conclusions: conclusions(runs),
    }
}

fn table(runs: &[StackRun]) -> Table {
    let mut t = Table::new(&[
        "substeps",
        "relax passes",
        "drift (mm)",
        "penetration (mm)",
        "sag (mm)",
        "contact passes / step",
        "µs / step",
    ]);
    for r in runs {
        t.row(vec![
            r.substeps.to_string(),
            r.relax.to_string(),
            sig(r.drift * 1e3),
            sig(r.penetration * 1e3),
            sig(r.sag * 1e3),
            r.passes().to_string(),
            sig(r.us_per_step),
        ]);
    }
    t
}

fn conclusions(runs: &[StackRun]) -> Vec<String> {
    let find = |s: u32, r: u32| runs.iter().find(|x| x.substeps == s && x.relax == r);
    let mut out = Vec::new();
    if let (Some(d), Some(one)) = (find(4, 2), find(4, 1)) {
        out.push(format!(
            "At the default (4 substeps, 2 relax passes) the stack drifts {} mm and sags {} mm \
             for {} µs per step; one relax pass drifts {} mm for {} µs.",
            sig(d.drift * 1e3),
            sig(d.sag * 1e3),
            sig(d.us_per_step),
            sig(one.drift * 1e3),
            sig(one.us_per_step),
        ));
    }
    let fell: Vec<String> = runs
        .iter()
        .filter(|r| r.sag > 1.0)
        .map(|r| format!("{} × {}", r.substeps, r.relax))
        .collect();
    if !fell.is_empty() {
        out.push(format!(
            "With too few substeps the stack falls over (sag above 1 m): {} (substeps × relax \
             passes). Stiffer contacts need shorter substeps; with fewer than 4 substeps of a \
             60 Hz step the default 60 Hz contacts are more than a quarter of the substep rate, \
             Box2D's bound. (Clamping the stiffness to that bound, as Box2D does, was tried: it \
             made 2 substeps × 3 relax passes fall too, so it is not done.)",
            fell.join(", ")
        ));
    }
    if let (Some(a), Some(b)) = (find(4, 1), find(8, 1)) {
        out.push(format!(
            "Substeps buy more than relax passes: 8 substeps × 1 relax pass sway {} mm for {} \
             µs per step, against {} mm for {} µs at 4 × 1.",
            sig(b.drift * 1e3),
            sig(b.us_per_step),
            sig(a.drift * 1e3),
            sig(a.us_per_step),
        ));
    }
    // Work counted in passes over the contacts (wall time on a shared machine is too noisy to
    // rank settings a few percent apart).
    if let Some(best) = runs
        .iter()
        .filter(|r| r.drift < 0.01)
        .min_by_key(|r| (r.passes(), r.substeps))
    {
        out.push(format!(
            "The cheapest setting that keeps the sway under the issue's 1 cm, counted in passes \
             over the contacts, is {} substeps × {} relax passes ({} passes, {} µs per step in \
             this run){}.",
            best.substeps,
            best.relax,
            best.passes(),
            sig(best.us_per_step),
            if (best.substeps, best.relax) == (4, 2) {
                ": the default"
            } else {
                ""
            }
        ));
    } else {
        out.push("No setting here keeps the drift under 1 cm.".into());
    }
    out
}
