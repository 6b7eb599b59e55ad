//! Output: ParaView-ready VTK XML unstructured grids with a `.pvd` time series, `history.csv`,
//! and the mesh written as a `.vtu`. Every file is written atomically (temporary file in the same
//! directory, then rename), so an interrupted run leaves only complete files.

pub mod atomic;
pub mod filter;
pub mod history;
pub mod stress;
pub mod vtk;
