//! The query index's tree as colliders come and go. Rebuilding the [`AabbTree`] over 10,000
//! boxes takes milliseconds; a game that spawns or despawns a bullet every step would pay that
//! at every step's first query. So a change keeps the tree: a collider that went has its slot
//! retired (its box emptied, its key never reported), one that came goes into a small second
//! tree of the recent colliders, rebuilt alone (`O(k log k)` for `k` recent), and the moved
//! ones are refitted as before. The whole is rebuilt once the recent ones pass about `2√n` or
//! the retired a quarter of the main tree, or once its refits have worn it (boxes that moved
//! apart: its surface-area cost grown by half). This is the simplest form of Bentley and Saxe's
//! static-to-dynamic transformation (1980): a static structure for the many, a small one for
//! the insertions, merged by rebuilding.
//!
//! Both trees hold *keys* (an item's index at its tree's build), and the caller's ids are
//! looked up by key, so any `u32` is an id (even the retired slots' marker) and a key retired
//! is never mistaken for a caller's id.

use super::index::IndexUpdate;
use super::tree::{AabbTree, RaySegment};
use crate::bounding::Aabb;
use glam::Vec3;

/// A visit of a pruning walk: an item's key and its distance, to a new limit or `None`.
type Visit<'a> = dyn FnMut(u32, f32) -> Option<f32> + 'a;

/// Marks a slot of the recent tree in [`ColliderTree::placed`].
const RECENT: u32 = 1 << 31;
/// No key (in the location scratch).
const NONE: u32 = u32::MAX;
/// How much the main tree's relative cost ([`AabbTree::relative_cost`]) may grow over its
/// build's before it is rebuilt: refits follow boxes that move apart (bodies flying across
/// the scene, an id handed to a collider elsewhere), and a tree whose nodes overlap more
/// makes every query visit more of them.
const WORN: f32 = 1.5;
/// Updates between two checks of the relative cost (it reads every node).
const CHECK_EVERY: u32 = 8;

/// The main tree, the recent colliders' tree and the retired slots (see the [module](self)).
#[derive(Clone, Debug, Default)]
pub struct ColliderTree {
    main: AabbTree,
    /// The caller's id of each main key.
    main_ids: Vec<u32>,
    /// Main slots retired since the main tree was built.
    retired: usize,
    recent: AabbTree,
    /// The caller's id of each recent key.
    recent_ids: Vec<u32>,
    /// The items of the last update in their order: the caller's id and where its box is (a
    /// main slot, or a recent slot with [`RECENT`] set), so that the same ids in the same
    /// order are refitted without a look-up.
    placed: Vec<(u32, u32)>,
    /// Scratch, all [`NONE`] between updates: the departure of each caller id.
    location: Vec<u32>,
    /// Scratch: the positions of items not at their last place.
    arrivals: Vec<u32>,
    /// Scratch: the ids and places of the last update's items not at their place now.
    departures: Vec<(u32, u32)>,
    /// Scratch: the positions of the items for the recent tree.
    recent_members: Vec<u32>,
    /// Scratch: items keyed for a build (the main tree's or the recent one's).
    keyed: Vec<(u32, Aabb)>,
    /// The main tree's relative cost when it was built.
    built_cost: Option<f32>,
    /// Updates since the cost was last checked.
    unchecked: u32,
    /// A stream found the tree worn ([`Self::finish_stream`]): the next update rebuilds.
    rebuild_due: bool,
}

impl ColliderTree {
    /// Takes this step's items (the caller's id and box), keeping what it can: the same ids
    /// in the same order are refitted, a few ids changed update the trees incrementally, and a
    /// change too large for that (or ids too sparse to index) rebuilds, as does a tree worn
    /// by its refits (its relative cost grown by half since its build, checked every
    /// `CHECK_EVERY` updates).
    pub fn update(&mut self, items: &[(u32, Aabb)]) -> IndexUpdate {
        match self.sync(items) {
            Some(kind) if !self.rebuild_due && !self.worn() => kind,
            _ => {
                self.rebuild(items);
                IndexUpdate::Rebuilt
            }
        }
    }

    /// Streams the `at`-th item's box in while the ids are the last update's, in order:
    /// `true` if `id` is the one the last update had there (its box is then written), `false`
    /// otherwise (nothing written; the caller collects the items and calls [`Self::update`],
    /// starting with [`Self::last_items`]). Saves a refit the list of items.
    #[inline]
    pub fn stream_box(&mut self, at: usize, id: u32, aabb: &Aabb) -> bool {
        match self.placed.get(at) {
            Some(&(old, place)) if old == id => {
                self.set_placed_box(place, aabb);
                true
            }
            _ => false,
        }
    }

    /// Appends the first `count` items of the last update (all of them if it had fewer) with
    /// the boxes they hold now.
    pub fn last_items(&self, count: usize, out: &mut Vec<(u32, Aabb)>) {
        let boxed = |&(id, place): &(u32, u32)| (id, self.placed_box(place));
        out.extend(self.placed.iter().take(count).map(boxed));
    }

    /// Writes the box of the item at `place` (a main slot, or a recent one with [`RECENT`]).
    #[inline]
    fn set_placed_box(&mut self, place: u32, aabb: &Aabb) {
        if place & RECENT == 0 {
            self.main.set_box(place as usize, aabb);
        } else {
            self.recent.set_box((place & !RECENT) as usize, aabb);
        }
    }

    /// The box of the item at `place`.
    fn placed_box(&self, place: u32) -> Aabb {
        if place & RECENT == 0 {
            self.main.box_at(place as usize)
        } else {
            self.recent.box_at((place & !RECENT) as usize)
        }
    }

    /// Ends a stream that gave every item of the last update in order ([`Self::stream_box`]
    /// `true` for each): the nodes refitted, or `false` when there were fewer items, or the
    /// tree is worn (the update then rebuilds it), and the caller goes on to [`Self::update`].
    pub fn finish_stream(&mut self, count: usize) -> bool {
        if count != self.placed.len() {
            return false;
        }
        self.main.refit_nodes();
        self.recent.refit_nodes();
        self.rebuild_due = self.worn();
        !self.rebuild_due
    }

    /// Whether the main tree's relative cost grew past [`WORN`] times its build's (checked
    /// every [`CHECK_EVERY`] calls, `false` in between).
    fn worn(&mut self) -> bool {
        self.unchecked += 1;
        if self.unchecked < CHECK_EVERY {
            return false;
        }
        self.unchecked = 0;
        match (self.main.relative_cost(), self.built_cost) {
            (Some(now), Some(built)) => now > WORN * built,
            _ => false,
        }
    }

    /// One main tree over every item; no recent or retired ones.
    fn rebuild(&mut self, items: &[(u32, Aabb)]) {
        self.keyed.clear();
        self.keyed.extend(
            items
                .iter()
                .enumerate()
                .map(|(key, &(_, b))| (key as u32, b)),
        );
        self.main.build(&self.keyed);
        self.main_ids.clear();
        self.main_ids.extend(items.iter().map(|&(id, _)| id));
        self.retired = 0;
        self.built_cost = self.main.relative_cost();
        self.unchecked = 0;
        self.rebuild_due = false;
        self.recent.build(&[]);
        self.recent_ids.clear();
        self.keyed.clear();
        self.placed.clear();
        let main = &self.main;
        self.placed.extend(
            items
                .iter()
                .enumerate()
                .map(|(key, &(id, _))| (id, main.slot_of_input(key) as u32)),
        );
    }

    /// Follows the items into the trees without rebuilding the main one: an item with the id
    /// the last update had at its position keeps its place (the common case: one comparison);
    /// the others are matched by id against the places left ([`Self::claim_arrivals`]), and
    /// what is left over retires (main) or goes into a rebuilt recent tree (new). `None` when
    /// the main tree should be rebuilt instead.
    fn sync(&mut self, items: &[(u32, Aabb)]) -> Option<IndexUpdate> {
        if self.main_ids.len() == self.retired {
            return None;
        }
        self.arrivals.clear();
        self.departures.clear();
        self.recent_members.clear();
        let kept = items.len().min(self.placed.len());
        for (i, (&(id, aabb), &(old, place))) in items.iter().zip(&self.placed).enumerate() {
            if id != old {
                self.arrivals.push(i as u32);
                self.departures.push((old, place));
            } else if place & RECENT == 0 {
                self.main.set_box(place as usize, &aabb);
            } else {
                // Its box is written below if nothing else changed; if something did, the
                // recent tree is rebuilt from the items.
                self.recent_members.push(i as u32);
            }
        }
        self.arrivals.extend(kept as u32..items.len() as u32);
        self.departures.extend_from_slice(&self.placed[kept..]);
        if self.arrivals.is_empty() && self.departures.is_empty() {
            for &i in &self.recent_members {
                let slot = self.placed[i as usize].1 & !RECENT;
                self.recent.set_box(slot as usize, &items[i as usize].1);
            }
            self.main.refit_nodes();
            self.recent.refit_nodes();
            return Some(IndexUpdate::Refitted);
        }
        self.placed.resize(items.len(), (0, 0));
        self.claim_arrivals(items)?;
        let live = self.main_ids.len() - self.retired;
        let recent_limit = 16 + 2 * (live as f64).sqrt() as usize;
        if self.recent_members.len() > recent_limit || 4 * self.retired > self.main_ids.len() {
            return None;
        }
        self.rebuild_recent(items);
        self.main.refit_nodes();
        Some(IndexUpdate::Updated)
    }

    /// Gives each arrival (an item not at its last place) the place its id left, if one did:
    /// a main slot takes its box, a recent one makes it a recent member again; arrivals with
    /// no place become recent members, and places no arrival took retire. `None` (nothing
    /// changed but boxes and places to be rebuilt) when the ids are too sparse to index by.
    fn claim_arrivals(&mut self, items: &[(u32, Aabb)]) -> Option<()> {
        let bound = 4 * items.len() + 1024;
        let ids = self.departures.iter().map(|d| d.0);
        let largest = ids
            .chain(self.arrivals.iter().map(|&i| items[i as usize].0))
            .max();
        if largest.is_some_and(|id| id as usize > bound) {
            return None;
        }
        let largest = largest.map_or(0, |id| id as usize);
        if self.location.len() <= largest {
            self.location.resize(largest + 1, NONE);
        }
        for (d, &(id, _)) in self.departures.iter().enumerate() {
            self.location[id as usize] = d as u32;
        }
        for &i in &self.arrivals {
            let (id, aabb) = items[i as usize];
            let d = self.location[id as usize];
            let place = if d == NONE {
                NONE
            } else {
                self.departures[d as usize].1
            };
            if place == NONE || place & RECENT != 0 {
                self.recent_members.push(i);
            } else {
                self.main.set_box(place as usize, &aabb);
                self.placed[i as usize] = (id, place);
            }
            if d != NONE {
                // Taken: a second arrival of the same id is new.
                self.departures[d as usize].1 = NONE;
            }
        }
        for &(id, place) in &self.departures {
            self.location[id as usize] = NONE;
            if place != NONE && place & RECENT == 0 {
                self.main.retire(place as usize);
                self.retired += 1;
            }
        }
        Some(())
    }

    /// The recent tree anew over the recent members, and their places.
    fn rebuild_recent(&mut self, items: &[(u32, Aabb)]) {
        self.keyed.clear();
        self.recent_ids.clear();
        for (key, &i) in self.recent_members.iter().enumerate() {
            let (id, aabb) = items[i as usize];
            self.keyed.push((key as u32, aabb));
            self.recent_ids.push(id);
        }
        self.recent.build(&self.keyed);
        for (key, &i) in self.recent_members.iter().enumerate() {
            let slot = self.recent.slot_of_input(key) as u32;
            self.placed[i as usize] = (items[i as usize].0, RECENT | slot);
        }
    }

    /// Items indexed (retired ones not counted).
    pub fn len(&self) -> usize {
        self.main_ids.len() - self.retired + self.recent_ids.len()
    }

    /// Whether no item is indexed.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// How many items sit in the recent tree and how many main slots are retired.
    pub fn pending(&self) -> (usize, usize) {
        (self.recent_ids.len(), self.retired)
    }

    /// The box around every item (`Aabb::EMPTY` when empty).
    pub fn bounds(&self) -> Aabb {
        self.main.bounds().union(&self.recent.bounds())
    }

    /// Calls `visit(id)` for every item whose box overlaps `aabb` (see
    /// [`AabbTree::overlapping`]).
    pub fn overlapping(&self, aabb: &Aabb, stack: &mut Vec<u32>, mut visit: impl FnMut(u32)) {
        for (tree, ids) in self.trees() {
            tree.overlapping(aabb, stack, |key| {
                if let Some(&id) = ids.get(key as usize) {
                    visit(id);
                }
            });
        }
    }

    /// Walks the items whose grown box `ray` enters before `max` (see
    /// [`AabbTree::along_ray`]); returns the limit the walk ended with (the least of `max`
    /// and what `visit` returned), for a walk of another tree to start from.
    pub fn along_ray(
        &self,
        ray: &RaySegment,
        grow: f32,
        max: f32,
        stack: &mut Vec<(u32, f32)>,
        visit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        let walk =
            |tree: &AabbTree, max, visit: &mut Visit| tree.along_ray(ray, grow, max, stack, visit);
        self.pruning_walk(max, walk, visit)
    }

    /// Walks the items whose box lies within `sqrt(max2)` of `p` (see
    /// [`AabbTree::near_point`]); returns the limit the walk ended with, as
    /// [`Self::along_ray`] does.
    pub fn near_point(
        &self,
        p: Vec3,
        max2: f32,
        stack: &mut Vec<(u32, f32)>,
        visit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        let walk =
            |tree: &AabbTree, max2, visit: &mut Visit| tree.near_point(p, max2, stack, visit);
        self.pruning_walk(max2, walk, visit)
    }

    /// A walk that prunes by a limit (`walk(tree, limit, visit)`, `visit` returning a new
    /// limit or `None`) over the recent tree, then the main one, each key handed to `visit`
    /// as the caller's id, the main walk starting from the limit the recent one left; returns
    /// the limit it ended with.
    fn pruning_walk(
        &self,
        mut limit: f32,
        mut walk: impl FnMut(&AabbTree, f32, &mut Visit),
        mut visit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        for (tree, ids) in self.trees() {
            walk(tree, limit, &mut |key, x| {
                let new_limit = visit(*ids.get(key as usize)?, x)?;
                limit = limit.min(new_limit);
                Some(new_limit)
            });
        }
        limit
    }

    /// The recent tree, then the main one, each with its keys' ids.
    fn trees(&self) -> [(&AabbTree, &[u32]); 2] {
        [
            (&self.recent, &self.recent_ids),
            (&self.main, &self.main_ids),
        ]
    }
}

#[cfg(test)]
#[path = "collider_tree_tests.rs"]
mod tests;
