//! The section's text: the table and what it shows.

use super::*;
use crate::markdown::{Section, Table, sig};

pub(super) fn section(runs: &[StackRun], seconds: f32) -> Section {
    let mut body = format!(
        "A stack of {BOXES} unit boxes (1 kg, friction 0.6) standing on a half-space through \
         `UrtoPlugins` with `SoftStepPlugin`, dt = 1/60 s, {seconds} s simulated, for each \
         number of solver substeps and of relax passes per substep (the other settings are the \
         defaults). Drift: the farthest any box got from where it started, over the run. \
         Penetration: the deepest overlap of two neighbours (or of the bottom box with the \
         ground) over the run. Sag: the top box's drop at the end. µs / step: wall time of the \
         whole physics step.\n\n"
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
        "µs / step",
    ]);
    for r in runs {
        t.row(vec![
            r.substeps.to_string(),
            r.relax.to_string(),
            sig(r.drift * 1e3),
            sig(r.penetration * 1e3),
            sig(r.sag * 1e3),
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
    if let (Some(a), Some(b)) = (find(1, 2), find(8, 2)) {
        out.push(format!(
            "Substeps buy stiffness: from 1 to 8 substeps (2 relax passes) the sag goes from {} \
             to {} mm and the penetration from {} to {} mm, while the step costs {:.1}× as much.",
            sig(a.sag * 1e3),
            sig(b.sag * 1e3),
            sig(a.penetration * 1e3),
            sig(b.penetration * 1e3),
            b.us_per_step / a.us_per_step.max(1e-9),
        ));
    }
    if let Some(best) = runs
        .iter()
        .filter(|r| r.drift < 0.01)
        .min_by(|a, b| a.us_per_step.total_cmp(&b.us_per_step))
    {
        out.push(format!(
            "The cheapest setting that keeps the drift under the issue's 1 cm is {} substeps × \
             {} relax passes ({} µs per step).",
            best.substeps,
            best.relax,
            sig(best.us_per_step)
        ));
    } else {
        out.push("No setting here keeps the drift under 1 cm.".into());
    }
    out
}
