//! The engine's kernels, by name: the matrix products (f32 with gemm's epilogues, and on f16
//! operands with tensor cores and without: a dense layer, a whole MLP, a training step's
//! forward, input-gradient and weight-gradient products, the weights' f16 copies), the chunks
//! of a split product added, convolutions and pools with their adjoints, and Adam. Each is its
//! file in `shaders/` (`products`, `convolutions`, `optimiser`) after the shared files it
//! names, by [`crate::kernel!`].

use nprt_gpu::KernelSource;

use crate::kernel;

pub const GEMM: KernelSource = kernel!(products / "gemm");
pub const COLUMN_SUM: KernelSource = kernel!(products / "column_sum");
pub const ADAM: KernelSource = kernel!(optimiser / "adam");
/// The frame path's half-precision dense layers (`half_layers`): the input's conversion, and
/// the product with tensor cores and without.
pub const HALF_ROWS: KernelSource = kernel!(products / "half_rows");
pub const HALF_DENSE: KernelSource = kernel!(products / "half_dense", products / "half_layer");
pub const HALF_DENSE_COOP: KernelSource = kernel!(
    products / "half_dense_coop",
    products / "coop_matrix",
    products / "half_layer",
    products / "coop_drain"
);
/// The frame path's whole MLP in half precision in one dispatch (`half_mlp`), without tensor
/// cores and with them.
pub const HALF_MLP_PLAIN: KernelSource =
    kernel!(products / "half_mlp_plain", products / "half_mlp");
pub const HALF_MLP_COOP: KernelSource = kernel!(
    products / "half_mlp_coop",
    products / "coop_matrix",
    products / "half_mlp",
    products / "coop_drain"
);
/// A mixed-precision training step's products (`half_products`): the dense layers' forward
/// and input-gradient products (the frame path's products under `half_train_layer`'s
/// epilogue), and the weight gradients, each with tensor cores and without.
pub const HALF_TRAIN: KernelSource =
    kernel!(products / "half_dense" as "half_train", products / "half_train_layer");
pub const HALF_TRAIN_COOP: KernelSource = kernel!(
    products / "half_dense_coop" as "half_train_coop",
    products / "coop_matrix",
    products / "half_train_layer",
    products / "coop_drain"
);
pub const HALF_WEIGHT_GRAD: KernelSource =
    kernel!(products / "half_weight_grad", products / "half_weight_sums");
/// A mixed-precision step's f16 copies of a weight, as stored and transposed, after Adam.
pub const HALF_WEIGHT_COPIES: KernelSource = kernel!(products / "half_weight_copies");
pub const HALF_WEIGHT_GRAD_COOP: KernelSource = kernel!(
    products / "half_weight_grad_coop",
    products / "coop_matrix",
    products / "half_weight_sums",
    products / "coop_drain"
);

/// Rows and columns of the tile a `gemm` workgroup computes.
pub const GEMM_TILE: u32 = 128;

/// Convolutional layers (nprt-net's U-Net and light encoder): convolutions, pools, the
/// U-Net's decoder inputs and bottleneck offsets, and their adjoints.
pub const CONV_FORWARD: KernelSource = kernel!(convolutions / "conv_forward");
pub const MAX_POOL: KernelSource = kernel!(convolutions / "max_pool");
pub const POOL_BACKWARD: KernelSource = kernel!(convolutions / "pool_backward");
pub const UPSAMPLE_CONCAT: KernelSource =
    kernel!(convolutions / "upsample_concat", convolutions / "upsample");
pub const UPSAMPLE_BACKWARD: KernelSource = kernel!(
    convolutions / "upsample_backward",
    convolutions / "upsample"
);
pub const PLANE_OFFSET: KernelSource = kernel!(convolutions / "plane_offset");
pub const OFFSET_BACKWARD: KernelSource = kernel!(convolutions / "offset_backward");
/// A convolution's gradients: at its input (the light encoder's and the U-Net's), and of its
/// weights and biases, per chunk of image rows.
pub const CONV_INPUT_BACKWARD: KernelSource = kernel!(convolutions / "conv_input_backward");
/// Threads `conv_input_backward` takes per input value: one per quarter of the channels.
pub const CONV_INPUT_BACKWARD_THREADS: usize = 4;
pub const CONV_WEIGHT_BACKWARD: KernelSource = kernel!(convolutions / "conv_weight_backward");

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether `want` appears in `source` in order, each a whole line (trimmed) of it.
    fn in_order(source: &str, want: &[String]) -> Result<(), String> {
        let mut lines = source.lines().map(str::trim);
        for w in want {
            if !lines.any(|l| l == w) {
                return Err(w.clone());
            }
        }
        Ok(())
    }

    /// The tensor-core products' 4 × 4 tile of 16 × 16 sums, spelt out in each kernel (WGSL
    /// has no arrays of cooperative matrices), described once here and each kernel held to it
    /// line by line: the 16 sums declared, a_i · b_j added into sum (i, j) (`half_mlp_coop` a
    /// column of the tile at a time, each from one load of W), and sum (i, j) drained to row
    /// block i and column block j.
    #[test]
    fn the_tensor_core_kernels_spell_out_one_4x4_tile() {
        let ij = || (0..4).flat_map(|i| (0..4).map(move |j| (i, j)));
        let sums: Vec<String> = (ij())
            .map(|(i, j)| format!("var c{i}{j} = coop_mat16x16<f32, C>();"))
            .collect();
        let by_row: Vec<String> = (ij())
            .map(|(i, j)| format!("c{i}{j} = coopMultiplyAdd(a{i}, b{j}, c{i}{j});"))
            .collect();
        let by_column: Vec<String> = (ij())
            .map(|(j, i)| format!("c{i}{j} = coopMultiplyAdd(a{i}, b, c{i}{j});"))
            .collect();
        let offset = |base: &str, block: usize| format!("{base} + {}u", 16 * block);
        let drains = |row: &dyn Fn(usize) -> String, col: &dyn Fn(usize) -> String| {
            (ij())
                .map(|(i, j)| format!("drain(c{i}{j}, sg, lane, {}, {});", row(i), col(j)))
                .collect::<Vec<String>>()
        };
        let blocks = drains(&|i| offset("row0", i), &|j| offset("col0", j));
        let layer = drains(&|i| format!("{}u", 16 * i), &|j| format!("col{j}"));
        let kernels = [
            (&HALF_DENSE_COOP, &by_row, &blocks),
            (&HALF_TRAIN_COOP, &by_row, &blocks),
            (&HALF_WEIGHT_GRAD_COOP, &by_row, &blocks),
            (&HALF_MLP_COOP, &by_column, &layer),
        ];
        for (kernel, products, drained) in kernels {
            let tile = [sums.clone(), products.clone(), drained.clone()].concat();
            if let Err(missing) = in_order(kernel.wgsl, &tile) {
                panic!("{}: no line '{missing}' where the tile needs it", kernel.name);
            }
        }
    }
}
