//! Gaussian-process surrogate: one squared-exponential ARD kernel shared by all ROI outputs,
//! hyperparameters by marginal likelihood, predictive mean and variance.

pub mod kernel;
pub mod likelihood;
pub mod predict;
pub mod train;

pub use kernel::SeArd;
pub use predict::GpPredictor;
pub use train::{fit_gp, GpModel, GpOptions};
