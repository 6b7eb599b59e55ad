//! Scenes: the TOML file a user writes ([`SceneSpec`]), its translation into a runnable
//! simulation ([`build`]: node sets, parts, constraints and loads, the output plan, loop
//! settings, contact through [`contact_build`]), the run loop that drives it to its end and
//! writes the summary ([`run`]), the pilot of `palpa check` ([`pilot`]), and the palpation scene
//! built in memory ([`palpation`]).
//!
//! Errors name the file, and where possible the line and key: toml reports the line and key of
//! a syntax error, an unknown key or a wrong unit; checks after parsing (an unknown node set, an
//! unknown material) name the key path and the line where its value appears.

pub mod build;
pub mod bulk;
pub mod contact_build;
pub mod contact_def;
pub mod contact_spec;
pub mod curve_spec;
pub mod def;
mod kinematics;
mod locate;
mod loop_settings;
mod node_sets;
pub mod output_plan;
pub mod palpation;
mod palpation_scene;
mod parts;
pub mod phantom_spec;
pub mod pilot;
pub mod run;
pub mod spec;

pub use build::load_scene;
pub use def::Scene;
pub use spec::SceneSpec;
