//! palpa's explicit solver: hexahedral meshes, total-Lagrangian elements, the central-difference
//! time loop, scenes, and output.
#![warn(missing_docs)]

pub mod bc;
pub mod campaign;
pub mod contact_stage;
pub mod element;
pub mod forces;
pub mod generate;
pub mod hex;
pub mod mesh;
pub mod mesh_io;
pub mod model;
pub mod output;
pub mod palpation;
pub mod phantom;
pub mod run;
pub mod scene;
pub mod simulation;
pub mod voxel;

pub use mesh::Mesh;
pub use model::{Model, Part, SolverError};
