//! scene's integration tests, one binary (a test file each below; `cargo test -p scene --test
//! integration NAME` runs one). One binary instead of nineteen: each of them linked and
//! re-instantiated the solver's generic step loop, 20 s of a clean CI build apiece.

mod bulk_knob;
mod common;
mod compression_block;
mod contact_defaults;
mod contact_force_control;
mod contact_hertz;
mod contact_punch;
mod contact_smoothness;
mod damaged_outputs;
mod determinism;
mod erosion;
mod global_step;
mod hourglass_modulus;
mod mass_scaling;
mod mesh_files;
mod numbering;
mod pilot;
mod run_guards;
mod stable_step;
mod subcycling;
