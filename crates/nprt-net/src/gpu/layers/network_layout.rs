//! Where each tensor of a network lies in the flat parameter buffers, in the network's own
//! structure (encoder blocks, tracks, layers), as the training step's dispatches address them.

use crate::gpu::kernels::HALF_WEIGHT_COPIES;
use crate::gpu::layers::layer_at::DenseAt;
use crate::gpu::layers::light_basis::BasisAt;
use crate::gpu::layers::light_encoder::EncoderAt;
use crate::gpu::layers::parameters::ParameterLayout;
use crate::gpu::products::half_layers::{half_weight_halves, pad16, HalfLayers, HalfWeight};
use crate::network::activation::Activation;
use crate::network::encoder::CODE_SIZE;
use crate::network::light_entry::LightEntry;
use crate::network::light_model::LightModel;
use crate::network::mlp::Mlp;
use crate::network::nprt_net::NprtNet;
use crate::network::track_kind::TrackKind;
use crate::network::track_plan::{Net, TrackPlan};
use nprt_gpu::Span;
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice};

/// Layers a copying dispatch takes at most (`half_weight_copies.wgsl`'s tables).
const COPY_LAYERS: usize = 8;

pub struct MlpAt {
    pub layers: Vec<DenseAt>,
    pub activation: Activation,
    /// In a mixed-precision step, each layer's f16 weights (empty in f32).
    pub half: Vec<HalfCopies>,
}

impl MlpAt {
    /// Gives each layer f16 copies of its weight: the first layer's rows `[row, row + count)`
    /// (what it multiplies its input by), every other layer's whole.
    fn hold_half(&mut self, gpu: &GpuDevice, [row, count]: [usize; 2]) {
        let rows: Vec<[usize; 2]> = (self.layers.iter().enumerate())
            .map(|(i, l)| if i == 0 { [row, count] } else { [0, l.d_in] })
            .collect();
        let stored = gpu.half_weights(&zip_shapes(&rows, &self.layers, false));
        let transposed = gpu.half_weights(&zip_shapes(&rows, &self.layers, true));
        self.half = (rows.iter().zip(stored).zip(transposed))
            .map(|((&[row, count], stored), transposed)| HalfCopies {
                row,
                count,
                stored,
                transposed,
            })
            .collect();
    }

    /// The widest of its layers' inputs and outputs: what a row of a gradient between layers
    /// needs at most.
    pub fn widest(&self) -> usize {
        self.layers
            .iter()
            .map(|l| l.d_in.max(l.d_out))
            .max()
            .unwrap_or(0)
    }

    /// Each layer with its f16 copies, in a mixed-precision step.
    pub fn half_layers(
        &self,
    ) -> impl DoubleEndedIterator<Item = (&DenseAt, &HalfCopies)> + ExactSizeIterator {
        self.layers.iter().zip(&self.half)
    }

    /// The dispatches that copy the layers' current weights from `params` into both of their
    /// f16 copies: one for up to [`COPY_LAYERS`] layers (none in f32).
    pub fn half_refresh(&self, gpu: &GpuDevice, params: &wgpu::Buffer) -> Vec<Dispatch> {
        let layers: Vec<_> = self.half_layers().collect();
        (layers.chunks(COPY_LAYERS))
            .map(|group| {
                let mut shape = [[0; 4]; COPY_LAYERS];
                let mut at = [[0; 4]; COPY_LAYERS];
                let mut threads = 0;
                for (i, (layer, copies)) in group.iter().enumerate() {
                    let (n, k) = (layer.d_out, copies.count);
                    let offset = layer.weight.offset + copies.row * n;
                    shape[i] = [k, n, pad16(k), pad16(n)];
                    at[i] = [
                        offset,
                        copies.stored.offset,
                        copies.transposed.offset,
                        threads,
                    ];
                    threads += half_weight_halves(k, n) + half_weight_halves(n, k);
                }
                let mut p = vec![group.len(), threads, 0, 0];
                p.extend(shape.iter().chain(&at).flatten());
                let p: Vec<u32> = p.iter().map(|&v| v as u32).collect();
                let copies = group[0].1;
                let buffers: [&dyn Bind; 3] =
                    [params, &copies.stored.buffer, &copies.transposed.buffer];
                gpu.prepare(&HALF_WEIGHT_COPIES, &p, &buffers, groups_for(threads))
            })
            .collect()
    }
}

/// A network's light model on the device: the paper's encoder or the linear design's basis.
pub enum LightAt {
    Encoder(EncoderAt),
    Basis(BasisAt),
}

impl LightAt {
    /// The light code's values per lighting.
    pub fn code_size(&self) -> usize {
        match self {
            LightAt::Encoder(_) => CODE_SIZE,
            LightAt::Basis(b) => 3 * b.size,
        }
    }
}

/// One track's networks on the device.
pub struct TrackAt {
    pub kind: TrackKind,
    /// Where the light code enters (the track's, see [`LightEntry`]).
    pub light: LightEntry,
    /// The feature indices the track reads, in its input order.
    pub index: wgpu::Buffer,
    pub count: usize,
    /// Inputs per row: `count` plus the hash grid's encoding.
    pub width: usize,
    pub grid: Option<Span>,
    pub transfer: Option<MlpAt>,
    pub shading: MlpAt,
    /// Its networks in the order they run (the track's [`TrackPlan`]).
    pub plan: TrackPlan,
}

impl TrackAt {
    /// The network a step runs.
    pub fn mlp(&self, net: Net) -> &MlpAt {
        match net {
            Net::Transfer => self.transfer.as_ref().expect("a transfer step has its network"),
            Net::Shading => &self.shading,
        }
    }

    fn mlp_mut(&mut self, net: Net) -> &mut MlpAt {
        match net {
            Net::Transfer => self.transfer.as_mut().expect("a transfer step has its network"),
            Net::Shading => &mut self.shading,
        }
    }
}

/// A network's tensors in the flat buffers.
pub struct NetworkLayout {
    pub light: LightAt,
    pub tracks: Vec<TrackAt>,
}

impl NetworkLayout {
    /// The places of `net`'s tensors in `layout`; each track's input indices (and a fixed
    /// basis' functions) are uploaded to `gpu`, and with `half` the transport networks' f16
    /// weights are made there (zero until refreshed).
    pub fn new(gpu: &GpuDevice, layout: &ParameterLayout, net: &NprtNet, half: bool) -> Self {
        // Spans in the order the network visits its tensors: the light model's, then the
        // tracks'.
        let mut spans = layout.spans.iter().copied();
        let light = match &net.light {
            LightModel::Encoder(e) => LightAt::Encoder(EncoderAt::new(e, &mut spans)),
            LightModel::Basis(b) => LightAt::Basis(BasisAt::new(gpu, b, &mut spans)),
        };
        let tracks: Vec<TrackAt> = net
            .tracks
            .iter()
            .map(|t| {
                let index: Vec<u32> = t.kind.inputs().iter().map(|&i| i as u32).collect();
                let grid = t.grid.as_ref().map(|_| spans.next().expect("a grid span"));
                let transfer = t.transfer.as_ref().map(|s| mlp_at(s, &mut spans));
                TrackAt {
                    kind: t.kind,
                    light: t.light,
                    index: gpu.upload(&index),
                    count: index.len(),
                    width: t.width(),
                    grid,
                    transfer,
                    shading: mlp_at(&t.shading, &mut spans),
                    plan: t.plan(),
                }
            })
            .collect();
        let mut layout = NetworkLayout { light, tracks };
        if half {
            layout.hold_half(gpu);
        }
        layout
    }

    /// Gives the transport networks' layers f16 copies of their weights (zero until
    /// refreshed, [`Self::half_refresh`]): each MLP's first layer of the rows its own input
    /// multiplies, every other layer whole.
    pub fn hold_half(&mut self, gpu: &GpuDevice) {
        for t in &mut self.tracks {
            for step in t.plan.steps.clone() {
                (t.mlp_mut(step.net)).hold_half(gpu, [step.own_row, step.own_width]);
            }
        }
    }

    /// Drops the f16 copies: the transport networks run in f32 again.
    pub fn drop_half(&mut self) {
        for t in &mut self.tracks {
            t.transfer.iter_mut().for_each(|m| m.half.clear());
            t.shading.half.clear();
        }
    }

    /// The dispatches that copy the transport layers' current weights from `params` into
    /// their f16 copies, one per MLP (none in f32).
    pub fn half_refresh(&self, gpu: &GpuDevice, params: &wgpu::Buffer) -> Vec<Dispatch> {
        self.tracks
            .iter()
            .flat_map(|t| t.transfer.iter().chain([&t.shading]))
            .flat_map(|m| m.half_refresh(gpu, params))
            .collect()
    }
}

/// The layers of `stack`, their spans taken in order from `spans`.
pub fn mlp_at(stack: &Mlp, spans: &mut impl Iterator<Item = Span>) -> MlpAt {
    MlpAt {
        layers: (stack.layers.iter())
            .map(|l| DenseAt::new(l, spans))
            .collect(),
        activation: stack.activation,
        half: Vec::new(),
    }
}

/// The `[d_in, d_out]` shapes of layers' f16 copies of rows `[row, row + count)` each, as
/// stored or `transposed`.
fn zip_shapes(rows: &[[usize; 2]], layers: &[DenseAt], transposed: bool) -> Vec<[usize; 2]> {
    (rows.iter().zip(layers))
        .map(|(&[_, count], l)| match transposed {
            false => [count, l.d_out],
            true => [l.d_out, count],
        })
        .collect()
}

/// A dense layer's f16 copies of its weight rows `[row, row + count)`: as stored (the forward
/// product's right operand) and transposed (the input gradient's); an MLP's layers keep each
/// kind in one buffer.
pub struct HalfCopies {
    pub row: usize,
    pub count: usize,
    pub stored: HalfWeight,
    pub transposed: HalfWeight,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::products::half_layers::half_weight_bits;

    /// An MLP's f16 copies, made in one dispatch: its first layer's of rows 3..23 of a 30 × 21
    /// weight, its second's of a whole 21 × 7 one, each kind in one buffer (the second layer's
    /// past the first's). Each stored copy is the host's layout of its rows
    /// (`half_weight_bits`, what the frame path and `nprt export` read) and each transposed one
    /// its transpose, padding zero, each value within f16's rounding (a copy 1% off fails, and
    /// so does a second layer written over the first's).
    #[test]
    fn both_f16_copies_of_a_weight_come_from_one_dispatch() {
        if !GpuDevice::probe() || !GpuDevice::get().unwrap().half {
            return;
        }
        let gpu = GpuDevice::get().unwrap();
        let (row, count) = (3, 20);
        let shapes = [[30, 21], [21, 7]];
        let mut flat = vec![9.0; 5];
        let mut layers = Vec::new();
        for [d_in, d_out] in shapes {
            let offset = flat.len();
            flat.extend((0..d_in * d_out).map(|i| ((i * 37 % 101) as f32 - 50.0) / 7.0));
            layers.push(DenseAt {
                weight: Span {
                    offset,
                    len: d_in * d_out,
                },
                bias: Span { offset: 0, len: 0 },
                d_in,
                d_out,
            });
        }
        let params = gpu.upload(&flat);
        let mut mlp = MlpAt {
            layers,
            activation: Activation::Relu,
            half: Vec::new(),
        };
        mlp.hold_half(&gpu, [row, count]);
        let refresh = mlp.half_refresh(&gpu, &params);
        assert_eq!(refresh.len(), 1);
        gpu.submit(&refresh);
        let halves = |w: &HalfWeight, n: usize| -> Vec<f32> {
            let words = gpu.read(&w.buffer, (w.offset + n).div_ceil(2));
            let bits: &[u16] = bytemuck::cast_slice(&words);
            bits[w.offset..][..n]
                .iter()
                .map(|&b| half::f16::from_bits(b).to_f32())
                .collect()
        };
        assert_eq!(mlp.half[1].stored.offset, half_weight_halves(count, 21));
        for (layer, copies) in mlp.half_layers() {
            let d_out = layer.d_out;
            let start = layer.weight.offset + copies.row * d_out;
            let rows = &flat[start..][..copies.count * d_out];
            let k = copies.count;
            let transposed: Vec<f32> = (0..d_out * k)
                .map(|e| rows[(e % k) * d_out + e / k])
                .collect();
            for (w, want) in [
                (&copies.stored, half_weight_bits(rows, k, d_out)),
                (&copies.transposed, half_weight_bits(&transposed, d_out, k)),
            ] {
                let got = halves(w, want.len());
                for (e, (&g, &b)) in got.iter().zip(&want).enumerate() {
                    let v = half::f16::from_bits(b).to_f32();
                    assert!((g - v).abs() <= 1e-3 * v.abs(), "value {e}: {g}, not {v}");
                }
            }
        }
    }
}
