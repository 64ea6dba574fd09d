//! The contact rows of bodies that turn within a step, rebuilt as they turn.
//!
//! # Why
//! A contact's rows are built once a step (Box2D v3): the lever arms `r × d`, the angular
//! velocity changes per unit impulse `I⁻¹ (r × d)` and the effective masses, with each body's
//! world inverse inertia at the step's start. A body whose inertia differs between axes turns
//! that inertia with it, so after a turn of `θ` an impulse meant to change its momentum by
//! `r × J` changes it by `I(t) I₀⁻¹ (r × J)`: off by about `θ` times the ratio of its moments.
//! In 2D the inertia is a number and this never arises; in 3D a thin rod's moments differ by
//! a thousand times. The fourth probe threw a capsule 1 m long and 2 cm thick, spinning at
//! 30 rad/s, at a wall: the rows fixed for the step spun it about its length by hundreds of
//! rad/s, and it left with up to 30 times the energy it came with (135 times before the
//! stop's fix of the free flight, `free_rotation.rs`).
//!
//! # What
//! After each substep's move, a gyroscopic body (free to turn, moments not all equal) whose
//! turn since its rows were built, times its moments' ratio less one, exceeds
//! [`STALE_ROW_BOUND`] takes its world inverse inertia where it is now, and the rows of its
//! contacts are rebuilt (anchors, directions and accumulated impulses kept), as are the
//! rows of its joints solved one at a time (a thin capsule on a hinge, spun at 100 and
//! 185 rad/s, gained up to 288 and 340 times its energy). A scene without such bodies pays
//! one check of an empty list a substep; a cube or a ball never has one. Friction per patch
//! and the free ball joints solved four at a time keep the step's rows.

use super::ContactConstraint;
use super::batch::ContactBatches;
use super::body::{SolverBodies, free_inverse_inertia};
use glam::{Quat, Vec3};

/// How far a body's rows may drift before they are rebuilt: its turn since they were built
/// (rad) times its largest over its smallest moment, less one.
const STALE_ROW_BOUND: f32 = 0.05;

/// A body whose rows may go stale.
#[derive(Debug, Clone, Copy)]
struct TurningBody {
    slot: u32,
    /// Principal frame and inverse moments (`BodyParams::gyroscopic`).
    inertia: (Quat, Vec3),
    /// Its largest over its smallest moment, less one.
    ratio: f32,
    /// Where it was when its rows were built.
    built: Quat,
}

/// The step's gyroscopic bodies and the orientations their rows were built at.
#[derive(Debug, Default, Clone)]
pub struct TurnedRows {
    /// The bodies whose rows may go stale.
    bodies: Vec<TurningBody>,
    /// Per body slot: rebuilt in this substep (sized at the step's start, reset body by body).
    turned: Vec<bool>,
    /// Per constraint: rebuilt in this substep.
    rebuilt: Vec<bool>,
}

impl TurnedRows {
    /// Lists the step's bodies whose rows may go stale (at the step's start).
    pub fn begin(&mut self, bodies: &SolverBodies) {
        self.bodies.clear();
        for &slot in &bodies.gyroscopic {
            if let Some((frame, d)) = bodies.params[slot as usize].gyroscopic {
                self.bodies.push(TurningBody {
                    slot,
                    inertia: (frame, d),
                    ratio: d.max_element() / d.min_element() - 1.0,
                    built: bodies.orientations[slot as usize],
                });
            }
        }
        self.turned.clear();
        if !self.bodies.is_empty() {
            self.turned.resize(bodies.len(), false);
        }
    }

    /// Rebuilds the rows of the bodies that turned past [`STALE_ROW_BOUND`] (module docs);
    /// true when some did ([`Self::turned`] says which).
    pub fn refresh(
        &mut self,
        bodies: &mut SolverBodies,
        constraints: &mut [ContactConstraint],
        batches: &mut ContactBatches,
    ) -> bool {
        if self.bodies.is_empty() {
            return false;
        }
        let mut any = false;
        for body in &mut self.bodies {
            let slot = body.slot as usize;
            self.turned[slot] = false;
            let now = bodies.states[slot].delta_rotation * bodies.orientations[slot];
            if now.angle_between(body.built) * body.ratio <= STALE_ROW_BOUND {
                continue;
            }
            body.built = now;
            let (frame, d) = body.inertia;
            bodies.params[slot].inverse_inertia = free_inverse_inertia(now, frame, d);
            self.turned[slot] = true;
            any = true;
        }
        if !any {
            return false;
        }
        self.rebuilt.clear();
        for c in constraints.iter_mut() {
            let touched = self.turned[c.a as usize] || self.turned[c.b as usize];
            if touched {
                c.refresh_rows(&bodies.params);
            }
            self.rebuilt.push(touched);
        }
        let rebuilt = &self.rebuilt;
        batches.refresh_rows(constraints, |k| rebuilt[k]);
        true
    }

    /// Per body slot: whether the last [`Self::refresh`] took its inertia anew.
    pub fn turned(&self) -> &[bool] {
        &self.turned
    }
}
