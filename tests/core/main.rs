//! The core's tests (geometry, bounding volumes, hierarchies, contacts, CCD, broad phases,
//! mass properties, mesh files): everything that needs no ECS, in one test binary. Each test
//! binary links the whole dependency graph, bevy and rerun included, and linking 38 binaries
//! was most of the test command's time; these were 18 of them.
//!
//! One file per subject, as before: `cargo test --release --test core bvh_build` runs one.

#[path = "../ccd_common/mod.rs"]
mod ccd_common;
#[path = "../common/mod.rs"]
mod common;

mod broad_phase_props;
mod bv_properties;
mod bvh_build;
mod bvh_matches_brute_force;
mod bvh_refit_descend;
mod ccd_oracle;
mod ccd_parry;
mod ccd_robustness;
mod ccd_thin_wall;
mod contacts_oracle;
mod convex_oracle;
mod grid_props;
mod mass_properties;
mod mesh_contacts;
mod mesh_io;
mod region_sweep;
mod tri_tri_properties;
mod tri_tri_vs_parry;
mod triangle_box_vs_parry;
mod trimesh_brute_force;
