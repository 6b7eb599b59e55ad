//! Scenes: the TOML file a user writes, and its translation into a runnable [`Simulation`].
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
