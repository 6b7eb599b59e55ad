//! palpa's explicit solver: hexahedral meshes, total-Lagrangian elements, the central-difference
//! time loop, scenes, and output.
#![warn(missing_docs)]

pub mod mesh;

pub use mesh::Mesh;
