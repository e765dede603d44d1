//! A camera's pixels on the GPU kernels ([`GpuPixels`]): each block's inputs and what of the
//! network does not depend on the lighting, and the activations every camera's pixels run
//! through ([`Workspace`]), which the network keeps for the next camera.

use std::sync::{Arc, OnceLock};

use nprt_gpu::{Dispatch, PooledBuffer};

use crate::gpu::layers::network_forward::ForwardTargets;
use crate::gpu::layers::network_layout::MlpAt;
use crate::gpu::products::half_layers::Held;

/// The buffers a camera's pixels run their networks through, which the network keeps for the
/// next camera: a new viewpoint then allocates only what it keeps (on an H200, allocating
/// these afresh for every 512² frame cost more than its networks). Pixels share them: the
/// queue runs one submission after another, and each writes them before reading.
pub(super) struct Workspace {
    /// Rows they hold (the largest block).
    pub(super) rows: usize,
    /// Ping-pong activations: f32 and, where the networks run in half precision, f16 (rows
    /// padded to a multiple of 256 and columns to 16).
    pub(super) f32: [wgpu::Buffer; 2],
    pub(super) f16: Option<[wgpu::Buffer; 2]>,
    /// Each track's shading outputs (where a lighting change runs its shading network).
    pub(super) outputs: Vec<wgpu::Buffer>,
}

impl Workspace {
    pub(super) fn half(&self) -> bool {
        self.f16.is_some()
    }

    /// Where `m`'s forward pass writes through this workspace: its hidden layers' outputs in
    /// turn into the ping-pong activations (f16 in half precision, where the input made f16
    /// takes the first), its last into `out`.
    pub(super) fn targets<'a>(&'a self, m: &MlpAt, out: Held<'a>) -> ForwardTargets<'a> {
        let last = m.layers.len() - 1;
        ForwardTargets::Frame {
            outputs: (0..=last)
                .map(|i| match (i == last, &self.f16) {
                    (true, _) => out,
                    (false, Some(f16)) => Held::F16(&f16[(i + 1) % 2]),
                    (false, None) => Held::F32(&self.f32[(i + 1) % 2]),
                })
                .collect(),
            input16: self.f16.as_ref().map(|f16| &f16[0]),
        }
    }

    /// `buffer`'s rows as the networks run through this workspace hold them.
    pub(super) fn held<'a>(&self, buffer: &'a wgpu::Buffer) -> Held<'a> {
        match self.half() {
            true => Held::F16(buffer),
            false => Held::F32(buffer),
        }
    }
}

/// A camera's foreground pixels on the device and what of the network does not depend on the
/// lighting, with the buffers a lighting change reuses.
pub struct GpuPixels {
    /// Rows the networks run on: the foreground pixels, or every pixel of a G-buffer on the
    /// device (see [`super::DeviceShading::pixels_of_gbuffer`]).
    pub rows: usize,
    pub(super) chunks: Vec<PixelChunk>,
    pub(super) work: Arc<Workspace>,
    /// Radiance of every row, `rows × 3`.
    pub(super) rgb: PooledBuffer,
    /// What a lighting change records (see `GpuNetwork::radiance`), prepared at the first.
    pub(super) relight: OnceLock<Vec<Dispatch>>,
    /// The network that made these pixels, the one that may relight them.
    pub(super) network: u64,
}

impl GpuPixels {
    /// Radiance of every row (`rows × 3` f32), as the last radiance left it.
    pub fn rgb(&self) -> &wgpu::Buffer {
        &self.rgb
    }
}

pub(super) struct PixelChunk {
    pub(super) first: usize,
    pub(super) rows: usize,
    pub(super) features: PooledBuffer,
    /// Per track, what a lighting change leaves as it is: what its shading network's first
    /// layer reads besides the light code, ŝ (`rows × TRANSPORT_CODE`) or, for the baseline,
    /// the gathered inputs (`rows × width`), in f16 where the networks run in half precision;
    /// or, where the light enters at the combine, the shading network's outputs (f32).
    pub(super) kept: Vec<PooledBuffer>,
}
