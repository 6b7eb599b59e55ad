//! Rigid indenters and penalty contact for palpa: positions in, forces out.
//!
//! This crate knows nothing of materials or meshes beyond plain arrays: the solver hands it the
//! deformable body's boundary quads (node ids), per-face bulk modulus and element volume, nodal
//! masses, and each step the current positions and velocities; it adds the contact forces to the
//! solver's force array and reports, per indenter, the force, depth, contact area and largest
//! penetration. All quantities are SI (m, s, kg, N, Pa, J).
//!
//! - [`shape`]: analytic rigid shapes (sphere, capsule, cylinder, box, plane) with exact signed
//!   distances; [`trimesh`]: STL triangle meshes with a BVH and pseudo-normal signs;
//!   [`tessellate`]: quadrilateral surfaces and hollow hexahedral meshes of the analytic shapes.
//! - [`aabb`]: axis-aligned bounding boxes, for the shapes' bounds, the mesh's BVH and the
//!   contact stage's broad phase.
//! - [`indenter`]: indenters (unions of parts moving along a direction) and the two-finger
//!   [`HandSpec`] preset.
//! - [`curve`]: curves of time ([`Curve`]), for an indenter's motion and for the solver's
//!   boundary conditions.
//! - [`motion`]: prescribed displacement/velocity and force control.
//! - [`stage`]: the penalty contact stage ([`ContactStage`]): sampled surface-to-surface penalty,
//!   segment-based or soft stiffness, friction, broad phase, energy and time-step bound. The
//!   equations and their sources are in that module's doc.
//!
//! Typical use by a solver:
//! ```
//! use contact::*;
//! // A unit-square face at z = 0 under a sphere that moves down 1 mm over 1 ms.
//! let x0 = vec![[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.01, 0.01, 0.0], [0.0, 0.01, 0.0]];
//! let surface = ContactSurface {
//!     faces: vec![[0, 1, 2, 3]],
//!     face_bulk_modulus: vec![1e6],
//!     face_element_volume: vec![1e-6],
//! };
//! let finger = IndenterSpec {
//!     name: "finger".into(),
//!     parts: vec![ShapeSpec::Sphere { center: [0.005, 0.005, 0.005], radius: 0.005 }],
//!     direction: [0.0, 0.0, -1.0],
//!     motion: MotionSpec::Displacement {
//!         curve: Curve::SmoothStep { amplitude: 1e-3, duration: 1e-3, start: 0.0 },
//!     },
//!     friction: None,
//! };
//! let mut stage =
//!     ContactStage::new(&[finger], surface, &x0, &[1e-3; 4], ContactParams::default()).unwrap();
//! let mut f = vec![[0.0; 3]; 4];
//! stage.apply(1e-3, 1e-6, &x0, &[[0.0; 3]; 4], &mut f);
//! let s = &stage.indenters()[0];
//! // The body pushes the indenter back up (+z).
//! assert!(s.force[2] > 0.0 && s.reaction > 0.0 && s.max_penetration > 0.9e-3);
//! ```
#![warn(missing_docs)]
// `!(x > 0.0)` is deliberate throughout: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod aabb;
pub mod curve;
pub mod indenter;
pub mod motion;
pub mod shape;
pub mod stage;
pub mod tessellate;
pub mod trimesh;
mod vec3;

pub use aabb::Aabb;
pub use curve::Curve;
pub use indenter::{HandSpec, Indenter, IndenterSpec, IndenterState};
pub use motion::{ForceControl, MotionSpec};
pub use shape::{Shape, ShapeSpec};
pub use stage::{ContactParams, ContactStage, ContactSurface, PenaltyKind, RayHit};
pub use trimesh::TriMesh;

/// Errors building indenters or the contact stage.
#[derive(Debug, thiserror::Error)]
pub enum ContactError {
    /// Invalid input data.
    #[error("contact: {0}")]
    Invalid(String),
    /// A file could not be read.
    #[error("contact: {0}")]
    Io(String),
}
