//! The paper's multilayer perceptron: inputs (x, y, force), ReLU hidden layers
//! (64, 126, 256, 512 by default), a linear output per ROI element.

pub mod forward;
pub mod network;
pub mod train;

pub use forward::{DenseLayer, MlpPredictor};
pub use network::MlpParams;
pub use train::{
    train_mlp, AdamOptions, GdxOptions, MlpModel, MlpOptions, Optimiser, PAPER_HIDDEN,
};
