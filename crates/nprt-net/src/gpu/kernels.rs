//! The network kernels, by name: the light encoder's blocks, the track inputs (with the hash
//! grid's encoding), the matrix product and the combination into radiance, which the frame
//! path dispatches too, the inputs made from a G-buffer on the device (the frame path's), and
//! the training step's own, its batch gathered from a dataset on the device among them. A
//! kernel's source is its file in `shaders/`, in a folder by concept (`networks`: the dense
//! layers, their products and the tracks' combination; `encodings`: the inputs and the hash
//! grid; `light`: the light models; `losses`; `optimiser`; `convolutions`: the U-Net's and the
//! light encoder's), after the shared files it names (WGSL has no includes); those that read the track kinds begin with their table, generated from
//! `TrackKind` at first use.

use std::sync::LazyLock;

use crate::network::track_kind::kind_table_wgsl;
use nprt_gpu::KernelSource;

/// The kernel in `shaders/DIR/NAME.wgsl`, after the shared `shaders/DIR/PART.wgsl` files listed
/// (those with `enable` directives first: WGSL takes them only before any declaration); with
/// `as "OTHER"`, named OTHER (a main file under another epilogue).
macro_rules! kernel {
    ($dir:ident / $name:literal $(, $pdir:ident / $part:literal)*) => {
        kernel!($dir / $name as $name $(, $pdir / $part)*)
    };
    ($dir:ident / $file:literal as $name:literal $(, $pdir:ident / $part:literal)*) => {
        KernelSource {
            name: $name,
            wgsl: concat!(
                $(include_str!(concat!("shaders/", stringify!($pdir), "/", $part, ".wgsl")),)*
                include_str!(concat!("shaders/", stringify!($dir), "/", $file, ".wgsl"))
            ),
        }
    };
}

pub const ENCODER_BLOCK: KernelSource = kernel!(light / "encoder_block");
/// Threads `encoder_block` takes per output value: one per slot of its pooling window.
pub const ENCODER_BLOCK_THREADS: usize = 4;
pub const ENCODER_POOL_BACKWARD: KernelSource = kernel!(light / "encoder_pool_backward");
/// A convolution's gradients: at its input (the light encoder's and the U-Net's), and of its
/// weights and biases, per chunk of image rows.
pub const CONV_INPUT_BACKWARD: KernelSource = kernel!(convolutions / "conv_input_backward");
/// Threads `conv_input_backward` takes per input value: one per quarter of the channels.
pub const CONV_INPUT_BACKWARD_THREADS: usize = 4;
pub const CONV_WEIGHT_BACKWARD: KernelSource = kernel!(convolutions / "conv_weight_backward");
pub const TRACK_INPUTS: KernelSource = kernel!(encodings / "track_inputs", encodings / "hash_grid");
pub const GRID_BACKWARD: KernelSource =
    kernel!(encodings / "grid_backward", encodings / "hash_grid");
pub const GEMM: KernelSource = kernel!(networks / "gemm");
pub const COLUMN_SUM: KernelSource = kernel!(networks / "column_sum");
pub static COMBINE: LazyLock<KernelSource> =
    LazyLock::new(|| with_kinds(kernel!(networks / "combine", networks / "track_radiance")));
pub const RADIANCE_LOSS: KernelSource = kernel!(losses / "radiance_loss", losses / "loss_element");
/// The loss on transfer vectors (`--targets transfer`) and its gradient at them.
pub static TRANSFER_LOSS: LazyLock<KernelSource> = LazyLock::new(|| {
    with_kinds(kernel!(
        losses / "transfer_loss",
        networks / "track_radiance"
    ))
});
pub static TRACK_GRADIENT: LazyLock<KernelSource> = LazyLock::new(|| {
    with_kinds(kernel!(
        networks / "track_gradient",
        networks / "track_radiance"
    ))
});
pub const ADAM: KernelSource = kernel!(optimiser / "adam");
/// The linear design's light codes, the maps' projections on its basis, and the gradient of a
/// learned basis' functions.
pub const LIGHT_PROJECT: KernelSource = kernel!(light / "light_project");
pub const LIGHT_PROJECT_BACKWARD: KernelSource = kernel!(light / "light_project_backward");
pub const GATHER_SAMPLES: KernelSource =
    kernel!(encodings / "gather_samples", encodings / "pixel_features");
/// The network inputs of a G-buffer left on the device (nprt-render's frame path).
pub const GBUFFER_FEATURES: KernelSource =
    kernel!(encodings / "gbuffer_features", encodings / "pixel_features");

/// The frame path's half-precision dense layers (`half_layers`): the input's conversion, and
/// the product with tensor cores and without.
pub const HALF_ROWS: KernelSource = kernel!(networks / "half_rows");
pub const HALF_DENSE: KernelSource = kernel!(networks / "half_dense", networks / "half_layer");
pub const HALF_DENSE_COOP: KernelSource = kernel!(
    networks / "half_dense_coop",
    networks / "coop_matrix",
    networks / "half_layer",
    networks / "coop_drain"
);

/// The frame path's whole MLP in half precision in one dispatch (`half_mlp`), without tensor
/// cores and with them.
pub const HALF_MLP_PLAIN: KernelSource =
    kernel!(networks / "half_mlp_plain", networks / "half_mlp");
pub const HALF_MLP_COOP: KernelSource = kernel!(
    networks / "half_mlp_coop",
    networks / "coop_matrix",
    networks / "half_mlp",
    networks / "coop_drain"
);

/// A mixed-precision training step's products (`half_products`): the dense layers' forward
/// and input-gradient products (the frame path's products under `half_train_layer`'s
/// epilogue), and the weight gradients, each with tensor cores and without.
pub const HALF_TRAIN: KernelSource =
    kernel!(networks / "half_dense" as "half_train", networks / "half_train_layer");
pub const HALF_TRAIN_COOP: KernelSource = kernel!(
    networks / "half_dense_coop" as "half_train_coop",
    networks / "coop_matrix",
    networks / "half_train_layer",
    networks / "coop_drain"
);
pub const HALF_WEIGHT_GRAD: KernelSource =
    kernel!(networks / "half_weight_grad", networks / "half_weight_sums");
/// A mixed-precision step's f16 copies of a weight, as stored and transposed, after Adam.
pub const HALF_WEIGHT_COPIES: KernelSource = kernel!(networks / "half_weight_copies");
pub const HALF_WEIGHT_GRAD_COOP: KernelSource = kernel!(
    networks / "half_weight_grad_coop",
    networks / "coop_matrix",
    networks / "half_weight_sums",
    networks / "coop_drain"
);

/// The Deep Shading U-Net's layers (`unet_pass`): its convolutions, pools, decoder inputs,
/// bottleneck offsets and loss, and their adjoints.
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
pub const UNET_LOSS: KernelSource = kernel!(losses / "unet_loss", losses / "loss_element");

/// `kernel` after the track kinds' table, made once per process (a kernel's source lives as
/// long as the process).
fn with_kinds(kernel: KernelSource) -> KernelSource {
    KernelSource::joined(kernel.name, &[&kind_table_wgsl(), kernel.wgsl])
}

/// Rows and columns of the tile a `gemm` workgroup computes.
pub const GEMM_TILE: u32 = 128;
