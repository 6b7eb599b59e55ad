//! palpa's explicit core: hexahedral meshes and their files, total-Lagrangian elements, the
//! model, the element-force loop, the central-difference time loop with its force stages
//! (contact among them), boundary conditions, and output. Scenes (the `scene` crate), the phantom
//! (`phantom`) and campaigns (`campaign`) build on it; it depends on none of them.
#![warn(missing_docs)]

pub mod bc;
pub mod contact_stage;
pub mod element;
pub mod forces;
pub mod generate;
pub mod global_step;
pub mod hex;
pub mod mesh;
pub mod mesh_io;
pub mod model;
mod nodal_update;
pub mod output;
pub mod renumber;
pub mod simulation;
pub mod subcycle;

pub use mesh::Mesh;
pub use model::{Model, Part, SolverError};
