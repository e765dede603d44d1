//! The arithmetic our GPU kernels' dense layers run in: f32, or f16 weights and activations
//! with f32 sums, on tensor cores where the adapter has them. Frames (`nprt render`, `view`,
//! `bench frame`) take it, and so does training on the kernels (`nprt train --device gpu`),
//! which keeps f32 master weights either way.

use crate::choice::named_choice;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    #[default]
    F32,
    F16,
}

named_choice!(Precision, "precision", {
    F32 => "f32",
    F16 => "f16",
});
