//! The layers networks are made of: dense layers and their activations, MLPs, convolutions,
//! each of them [`crate::parameters::Parameters`] to a model file and the optimiser. The CPU
//! engine's passes over them are in `crate::cpu`.

pub mod activation;
pub mod conv;
pub mod dense;
pub mod mlp;
