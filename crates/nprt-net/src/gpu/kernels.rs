//! The networks' kernels, by name: the light encoder's blocks, the track inputs (with the hash
//! grid's encoding), the combination into radiance, which the frame path dispatches too, the
//! inputs made from a G-buffer on the device (the frame path's), the losses, the U-Net's
//! loss, and the training step's own, its batch gathered from a dataset on the device among
//! them; beside nprt-engine's (the matrix products, the convolutions and pools, and Adam),
//! re-exported here. A kernel's source is its file in `shaders/`, in a folder by concept
//! (`networks`: the tracks' combination; `encodings`: the inputs and the hash grid; `light`:
//! the light models; `losses`), after the shared files it
//! names (WGSL has no includes; [`nprt_engine::kernel!`]); those that read the track kinds
//! begin with their table, generated from `TrackKind` at first use.

use std::sync::LazyLock;

use crate::network::track_kind::kind_table_wgsl;
use nprt_engine::kernel;
use nprt_gpu::KernelSource;

// The products', the convolutions' and Adam's kernels, nprt-engine's, beside these.
pub use nprt_engine::gpu::kernels::*;

pub const ENCODER_BLOCK: KernelSource = kernel!(light / "encoder_block");
/// Threads `encoder_block` takes per output value: one per slot of its pooling window.
pub const ENCODER_BLOCK_THREADS: usize = 4;
pub const ENCODER_POOL_BACKWARD: KernelSource = kernel!(light / "encoder_pool_backward");
pub const TRACK_INPUTS: KernelSource = kernel!(encodings / "track_inputs", encodings / "hash_grid");
pub const GRID_BACKWARD: KernelSource =
    kernel!(encodings / "grid_backward", encodings / "hash_grid");
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
/// The linear design's light codes, the maps' projections on its basis, and the gradient of a
/// learned basis' functions.
pub const LIGHT_PROJECT: KernelSource = kernel!(light / "light_project");
pub const LIGHT_PROJECT_BACKWARD: KernelSource = kernel!(light / "light_project_backward");
pub const GATHER_SAMPLES: KernelSource =
    kernel!(encodings / "gather_samples", encodings / "pixel_features");
/// The network inputs of a G-buffer left on the device (nprt-render's frame path).
pub const GBUFFER_FEATURES: KernelSource =
    kernel!(encodings / "gbuffer_features", encodings / "pixel_features");

/// The Deep Shading U-Net's loss (its layers are nprt-engine's).
pub const UNET_LOSS: KernelSource = kernel!(losses / "unet_loss", losses / "loss_element");

/// `kernel` after the track kinds' table, made once per process (a kernel's source lives as
/// long as the process).
fn with_kinds(kernel: KernelSource) -> KernelSource {
    KernelSource::joined(kernel.name, &[&kind_table_wgsl(), kernel.wgsl])
}
