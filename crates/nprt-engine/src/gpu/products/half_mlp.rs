//! An MLP's layers in half precision in one dispatch (`half_mlp.wgsl`, after tiny-cuda-nn's
//! fully fused MLP): a workgroup takes 64 rows through every layer, their activations kept in
//! workgroup memory between layers. Three passes use it: a frame's forward pass; a training
//! step's, which also writes what backward reads (the input and each hidden layer's output
//! as f16 rows, and its pre-activation); and a training step's input gradients from the last
//! layer down, on the transposed weights, each layer's gradient times the activation's
//! derivative at the pre-activation the forward pass kept, and kept for the weight gradients.
//! Where the adapter has cooperative matrices the products run on tensor cores
//! (`half_mlp_coop`), elsewhere without (`half_mlp_plain`). An MLP it cannot hold (a layer
//! wider than 256 or more than 8 layers), or an adapter with less workgroup memory than it
//! takes (32 KiB, 36 on tensor cores), runs a layer a dispatch instead (`half_layers`).

use crate::gpu::kernels::{HALF_MLP_COOP, HALF_MLP_PLAIN};
use crate::gpu::products::half_layers::{pad16, HalfWeight, Held, HALF_ROW_BLOCK};
use crate::gpu::products::operands::Bias;
use nprt_gpu::{Bind, Dispatch, GpuDevice};

/// The widest layer input or output (padded to 16) a fused pass holds, its most layers, and the
/// rows a workgroup takes.
const MAX_WIDTH: usize = 256;
const MAX_LAYERS: usize = 8;
const ROWS: usize = 64;

/// One layer of a fused pass: its f16 weight (in the buffer the pass's layers share), its
/// input's padded width, where its bias starts in the pass's biases (the first layer's has its
/// own binding), its activation (`half_mlp.wgsl`'s codes: 0 linear, 1 ReLU, 2 SIREN; 3 and 4
/// their derivatives, backward) and, in training, where its f16 output lies in
/// [`FusedIo::y16`] and its pre-activation in [`FusedIo::pre`] (values from the buffer's
/// start, each place a multiple of the storage-binding alignment).
pub struct FusedLayer<'a> {
    pub weight: &'a HalfWeight,
    pub k_pad: usize,
    pub bias_at: usize,
    pub activation: u32,
    pub held_at: usize,
    pub pre_at: usize,
}

/// Workgroup memory a fused pass takes: its rows' activations as f16, and on tensor cores a
/// subgroup's tile of sums each (`coop_drain`) and the pass count.
fn workgroup_bytes(tensor_cores: bool) -> u32 {
    let tiles = if tensor_cores { 4 * 256 * 4 + 4 } else { 0 };
    (ROWS * MAX_WIDTH * 2 + tiles) as u32
}

/// Whether a fused pass on `gpu` holds `layers`: at most [`MAX_LAYERS`], each at most
/// [`MAX_WIDTH`] in and out, their weights in one buffer, and the adapter's workgroup memory
/// enough for it (an adapter with less runs a layer a dispatch).
pub fn fits(gpu: &GpuDevice, layers: &[FusedLayer]) -> bool {
    let shared = layers
        .windows(2)
        .all(|w| w[0].weight.buffer == w[1].weight.buffer);
    let memory = gpu.device.limits().max_compute_workgroup_storage_size;
    (1..=MAX_LAYERS).contains(&layers.len())
        && shared
        && workgroup_bytes(gpu.tensor_cores) <= memory
        && layers
            .iter()
            .all(|l| l.k_pad <= MAX_WIDTH && l.weight.n_pad <= MAX_WIDTH)
}

/// What a fused pass reads and writes beside its layers' weights.
pub struct FusedIo<'a> {
    pub rows: usize,
    /// f32 rows of `x_cols` values (made f16 as they are read), or f16 rows of the first
    /// layer's padded width.
    pub x: Held<'a>,
    pub x_cols: usize,
    /// The first layer's bias, and the buffer the others' lie in (`None`: they have none, as
    /// in a backward pass).
    pub bias0: Bias<'a>,
    pub biases: Option<&'a wgpu::Buffer>,
    /// f16 rows padded as [`Held::F16`] holds them, each layer's from its `held_at`: the last
    /// layer's output where `out16`, and with `kept_input` (its place) the input and every
    /// hidden layer's output too (what a training step's backward reads).
    pub y16: Option<&'a wgpu::Buffer>,
    pub out16: bool,
    pub kept_input: Option<usize>,
    /// The last layer's output as f32 rows of its width.
    pub y32: Option<&'a wgpu::Buffer>,
    /// The hidden layers' pre-activations, each from its `pre_at`, and what the pass does
    /// with them.
    pub pre: Option<(&'a wgpu::Buffer, Pre)>,
}

/// What a fused pass does with the hidden layers' pre-activations ([`FusedIo::pre`]).
#[derive(Clone, Copy, PartialEq)]
pub enum Pre {
    /// Writes them (a training step's forward pass).
    Keep,
    /// Reads them for the activations' derivatives (a backward pass).
    Derive,
}

/// The dispatch of `layers` over `io`'s rows (`half_mlp.wgsl`). The layers must [`fits`].
pub fn half_mlp(gpu: &GpuDevice, layers: &[FusedLayer], io: &FusedIo) -> Dispatch {
    assert!(fits(gpu, layers), "an MLP a fused pass cannot hold");
    let (x16, x32, x_f32) = match io.x {
        Held::F16(b) => (b, &gpu.empty, 0),
        Held::F32(b) => (&gpu.empty, b, 1),
    };
    let (bias0_mode, bias0, bias0_at, group_of) = io.bias0.binding(gpu);
    let mut params = vec![io.rows, layers.len(), x_f32, io.x_cols];
    params.extend([io.out16, io.y32.is_some(), io.kept_input.is_some()].map(usize::from));
    params.extend([
        usize::from(matches!(io.pre, Some((_, Pre::Keep)))),
        io.kept_input.unwrap_or(0),
        bias0_mode,
        bias0_at,
        usize::from(io.biases.is_some()),
    ]);
    let mut shape = [[0; 4]; MAX_LAYERS];
    let mut at = [[0; 4]; MAX_LAYERS];
    for (i, l) in layers.iter().enumerate() {
        let w = l.weight;
        debug_assert_eq!(l.k_pad, pad16(l.k_pad));
        shape[i] = [l.k_pad, w.d_out, w.n_pad, l.activation as usize];
        at[i] = [w.offset, l.bias_at, l.held_at, l.pre_at];
    }
    params.extend(shape.iter().chain(&at).flatten());
    let kernel = match gpu.tensor_cores {
        true => &HALF_MLP_COOP,
        false => &HALF_MLP_PLAIN,
    };
    // Every row the f16 buffers hold (a multiple of HALF_ROW_BLOCK), as a layer a dispatch
    // writes them.
    let groups = io.rows.next_multiple_of(HALF_ROW_BLOCK) / ROWS;
    let weights = &layers[0].weight.buffer;
    let buffers: [&dyn Bind; 9] = [
        x16,
        x32,
        weights,
        bias0,
        io.biases.unwrap_or(&gpu.empty),
        group_of,
        io.y16.unwrap_or(&gpu.spare),
        io.y32.unwrap_or(&gpu.spare),
        io.pre.map_or(&gpu.spare, |(b, _)| b),
    ];
    let params: Vec<u32> = params.iter().map(|&v| v as u32).collect();
    gpu.prepare(kernel, &params, &buffers, [groups as u32, 1])
}

#[cfg(test)]
mod tests;
