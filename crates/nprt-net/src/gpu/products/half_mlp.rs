//! A whole MLP's forward pass in half precision in one dispatch, a frame's or a training step's
//! (`half_mlp.wgsl`, after tiny-cuda-nn's fully fused MLP): a workgroup takes 64 rows through
//! every layer, their activations kept in workgroup memory between layers; a training step's
//! pass also writes what backward reads (the input and each hidden layer's output as f16 rows,
//! and its pre-activation). Where the adapter
//! has cooperative matrices the products run on tensor cores (`half_mlp_coop`), elsewhere
//! without (`half_mlp_plain`). An MLP it cannot hold (a layer wider than 256 or more than 8
//! layers), or an adapter with less workgroup memory than it takes (32 KiB, 36 on tensor
//! cores), runs a layer a dispatch instead (`half_layers`).

use crate::gpu::kernels::{HALF_MLP_COOP, HALF_MLP_PLAIN};
use crate::gpu::products::half_layers::{pad16, HalfWeight, Held, HALF_ROW_BLOCK};
use crate::gpu::products::operands::Bias;
use nprt_gpu::{Dispatch, GpuDevice};

/// The widest layer input or output (padded to 16) a fused pass holds, its most layers, and the
/// rows a workgroup takes.
const MAX_WIDTH: usize = 256;
const MAX_LAYERS: usize = 8;
const ROWS: usize = 64;

/// One layer of a fused pass: its f16 weight (in the buffer the pass's layers share), its
/// input's padded width, where its bias starts in the pass's biases (the first layer's has its
/// own binding) and its activation (0 linear, 1 ReLU, 2 SIREN).
pub struct FusedLayer<'a> {
    pub weight: &'a HalfWeight,
    pub k_pad: usize,
    pub bias_at: usize,
    pub activation: u32,
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

/// Where a training step's fused pass keeps what backward reads: the input as f16 rows from
/// `input_at` of `held`, and per hidden layer `[its f16 output's start in held, its
/// pre-activation's in pre]` (in values, each a multiple of the storage-binding alignment).
pub struct Kept<'a> {
    pub held: &'a wgpu::Buffer,
    pub pre: &'a wgpu::Buffer,
    pub input_at: usize,
    pub layers: Vec<[usize; 2]>,
}

/// The dispatch of `layers` over `rows` rows of `x` into `y`: `x` f32 rows of `x_cols` values
/// (made f16 as they are read) or f16 rows of the first layer's padded width; `y` the last
/// layer's f32 rows of its width or f16 rows padded as [`Held::F16`] holds them. `bias0` is the
/// first layer's bias, `biases` the buffer the others' lie in; with `kept` (training, an f32
/// input and output) the pass also writes what backward reads there. The layers must
/// [`fits`].
#[allow(clippy::too_many_arguments)]
pub fn half_mlp(
    gpu: &GpuDevice,
    rows: usize,
    (x, x_cols): (Held, usize),
    layers: &[FusedLayer],
    bias0: Bias,
    biases: &wgpu::Buffer,
    y: Held,
    kept: Option<&Kept>,
) -> Dispatch {
    assert!(fits(gpu, layers), "an MLP a fused pass cannot hold");
    let (x16, x32, x_f32) = match x {
        Held::F16(b) => (b, &gpu.empty, 0),
        Held::F32(b) => (&gpu.empty, b, 1),
    };
    let (mut y16, y32, half_out) = match y {
        Held::F16(b) => (b, &gpu.spare, 1),
        Held::F32(b) => (&gpu.spare, b, 0),
    };
    let (bias0_mode, bias0, bias0_at, group_of) = bias0.binding(gpu);
    let (mut z, mut input_at) = (&gpu.spare, 0);
    let mut shape = [[0; 4]; MAX_LAYERS];
    let mut at = [[0; 4]; MAX_LAYERS];
    if let Some(k) = kept {
        assert!(
            x_f32 == 1 && half_out == 0,
            "a training pass from f32 rows to f32 rows"
        );
        (y16, z, input_at) = (k.held, k.pre, k.input_at);
        for (at, &[held_at, pre_at]) in at.iter_mut().zip(&k.layers) {
            at[2..].copy_from_slice(&[held_at, pre_at]);
        }
    }
    for (i, l) in layers.iter().enumerate() {
        let w = l.weight;
        debug_assert_eq!(l.k_pad, pad16(l.k_pad));
        shape[i] = [l.k_pad, w.d_out, w.n_pad, l.activation as usize];
        at[i][..2].copy_from_slice(&[w.offset, l.bias_at]);
    }
    let mut params = vec![rows, layers.len(), x_f32, x_cols, half_out];
    params.extend([
        usize::from(kept.is_some()),
        input_at,
        bias0_mode,
        bias0_at,
        0,
        0,
        0,
    ]);
    params.extend(shape.iter().chain(&at).flatten());
    let kernel = match gpu.tensor_cores {
        true => &HALF_MLP_COOP,
        false => &HALF_MLP_PLAIN,
    };
    // Every row the f16 buffers hold (a multiple of HALF_ROW_BLOCK), as a layer a dispatch
    // writes them.
    let groups = rows.next_multiple_of(HALF_ROW_BLOCK) / ROWS;
    let weights = &layers[0].weight.buffer;
    gpu.prepare(
        kernel,
        &params.iter().map(|&v| v as u32).collect::<Vec<_>>(),
        &[x16, x32, weights, bias0, biases, group_of, y16, y32, z],
        [groups as u32, 1],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::products::half_layers::{half_weight_bits, held_halves, HalfLayers};

    /// f16's rounding of `v`.
    fn round16(v: f32) -> f32 {
        half::f16::from_f32(v).to_f32()
    }

    /// A value of a fixed pattern in [-scale / 2, scale / 2).
    fn value(i: usize, scale: f32) -> f32 {
        ((i * 7919 % 211) as f32 / 211.0 - 0.5) * scale
    }

    /// An MLP `widths[0]` → … → `widths[last]` (ReLU, then linear) on the device and on the
    /// host: weights and biases of a fixed pattern, the host's weights rounded to f16 as the
    /// device holds them, every bias but the first in `params`.
    struct Mlp {
        shapes: Vec<[usize; 2]>,
        weights: Vec<HalfWeight>,
        host: Vec<(Vec<f32>, Vec<f32>)>,
        params: wgpu::Buffer,
        bias_at: Vec<usize>,
    }

    impl Mlp {
        fn new(gpu: &GpuDevice, widths: &[usize]) -> Self {
            let shapes: Vec<[usize; 2]> = widths.windows(2).map(|w| [w[0], w[1]]).collect();
            let weights = gpu.half_weights(&shapes);
            let mut host = Vec::new();
            let mut biases = vec![0.0; 64];
            let mut bias_at = Vec::new();
            for (l, (&[d_in, d_out], w)) in shapes.iter().zip(&weights).enumerate() {
                let scale = 2.0 / (d_in as f32).sqrt();
                let weight: Vec<f32> = (0..d_in * d_out).map(|i| value(i + l, scale)).collect();
                let bits = half_weight_bits(&weight, d_in, d_out);
                gpu.queue
                    .write_buffer(&w.buffer, 2 * w.offset as u64, bytemuck::cast_slice(&bits));
                let bias: Vec<f32> = (0..d_out).map(|j| value(j + 3 * l, 0.2)).collect();
                bias_at.push(biases.len());
                biases.extend(&bias);
                biases.resize(biases.len().next_multiple_of(64), 0.0);
                host.push((weight.iter().map(|&v| round16(v)).collect(), bias));
            }
            let params = gpu.upload(&biases);
            Mlp {
                shapes,
                weights,
                host,
                params,
                bias_at,
            }
        }

        fn layers(&self) -> Vec<FusedLayer<'_>> {
            (self.weights.iter().enumerate())
                .map(|(l, w)| FusedLayer {
                    weight: w,
                    k_pad: pad16(self.shapes[l][0]),
                    bias_at: self.bias_at[l],
                    activation: u32::from(l + 1 < self.shapes.len()),
                })
                .collect()
        }

        /// Each layer's pre-activation and output over `rows` rows of `x` on the host in f32,
        /// each hidden output rounded to f16 as the pass holds it; row i's first bias is
        /// `bias0(i)`.
        fn host_layers(
            &self,
            x: &[f32],
            rows: usize,
            bias0: &dyn Fn(usize) -> Vec<f32>,
        ) -> Vec<[Vec<f32>; 2]> {
            let mut y: Vec<f32> = x.iter().map(|&v| round16(v)).collect();
            let mut kept = Vec::new();
            for (l, (w, b)) in self.host.iter().enumerate() {
                let [d_in, d_out] = self.shapes[l];
                let hidden = l + 1 < self.shapes.len();
                let pre: Vec<f32> = (0..rows * d_out)
                    .map(|e| {
                        let (i, j) = (e / d_out, e % d_out);
                        let sum: f32 = (0..d_in).map(|k| y[i * d_in + k] * w[k * d_out + j]).sum();
                        sum + if l == 0 { bias0(i)[j] } else { b[j] }
                    })
                    .collect();
                y = match hidden {
                    true => pre.iter().map(|&v| round16(v.max(0.0))).collect(),
                    false => pre.clone(),
                };
                kept.push([pre, y.clone()]);
            }
            kept
        }
    }

    /// `rows` rows of `cols` f16 values as `Held::F16` holds them, from a buffer of them.
    fn held_rows(
        gpu: &GpuDevice,
        buffer: &wgpu::Buffer,
        at: usize,
        rows: usize,
        cols: usize,
    ) -> Vec<f32> {
        let halves = held_halves(rows, cols);
        let words = gpu.read(buffer, (at + halves).div_ceil(2));
        let bits: &[u16] = bytemuck::cast_slice(&words);
        (bits[at..at + halves].iter())
            .map(|&b| half::f16::from_bits(b).to_f32())
            .collect()
    }

    /// The largest difference of `got` from `want` over `want`'s largest value.
    fn relative(got: &[f32], want: &[f32]) -> f32 {
        let peak = want.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        let worst = (got.iter().zip(want)).fold(0.0f32, |m, (g, w)| m.max((g - w).abs()));
        worst / peak
    }

    /// `values` (rows of `cols`) as held f16 rows: padded with zeros to 16 columns and to the
    /// held rows.
    fn padded(values: &[f32], rows: usize, cols: usize) -> Vec<f32> {
        let k_pad = pad16(cols);
        let mut out = vec![0.0; held_halves(rows, cols)];
        for (e, &v) in values.iter().enumerate() {
            out[e / cols * k_pad + e % cols] = v;
        }
        out
    }

    /// A fused pass over `rows` rows of `widths`' MLP (the first layer's bias apart) against
    /// the host's: the largest difference over the largest output.
    fn fused_error(widths: &[usize], rows: usize, half_in: bool, half_out: bool) -> f32 {
        let gpu = GpuDevice::get().unwrap();
        let mlp = Mlp::new(&gpu, widths);
        let values: Vec<f32> = (0..rows * widths[0]).map(|i| value(i, 2.0)).collect();
        let x_buffer = match half_in {
            true => {
                let f16 = padded(&values, rows, widths[0]);
                let bits: Vec<u16> = f16
                    .iter()
                    .map(|&v| half::f16::from_f32(v).to_bits())
                    .collect();
                gpu.upload(&bits)
            }
            false => gpu.upload(&values),
        };
        let x_held = match half_in {
            true => Held::F16(&x_buffer),
            false => Held::F32(&x_buffer),
        };
        let last = *widths.last().unwrap();
        let out = match half_out {
            true => gpu.half_buffer(held_halves(rows, last)),
            false => gpu.buffer(rows * last),
        };
        let y = match half_out {
            true => Held::F16(&out),
            false => Held::F32(&out),
        };
        let bias0 = gpu.upload(&mlp.host[0].1);
        let (layers, bias0) = (mlp.layers(), Bias::Column(&bias0, 0));
        let x = (x_held, widths[0]);
        let dispatch = half_mlp(&gpu, rows, x, &layers, bias0, &mlp.params, y, None);
        gpu.submit([&dispatch]);
        let got: Vec<f32> = match half_out {
            true => {
                let held = held_rows(&gpu, &out, 0, rows, last);
                let n_pad = pad16(last);
                (0..rows * last)
                    .map(|e| held[e / last * n_pad + e % last])
                    .collect()
            }
            false => gpu.read(&out, rows * last),
        };
        let want = mlp.host_layers(&values, rows, &|_| mlp.host[0].1.clone());
        relative(&got, &want[want.len() - 1][1])
    }

    /// The workgroup memory `fits` asks the adapter for is what the kernels declare: their
    /// `var<workgroup>` variables' sizes, as naga lays them out.
    #[test]
    fn the_workgroup_memory_asked_for_is_what_the_kernels_declare() {
        for (kernel, tensor_cores) in [(&HALF_MLP_PLAIN, false), (&HALF_MLP_COOP, true)] {
            let module = naga::front::wgsl::parse_str(kernel.wgsl).unwrap();
            let mut layouter = naga::proc::Layouter::default();
            layouter.update(module.to_ctx()).unwrap();
            let declared: u32 = (module.global_variables.iter())
                .filter(|(_, v)| v.space == naga::AddressSpace::WorkGroup)
                .map(|(_, v)| layouter[v.ty].size)
                .sum();
            assert_eq!(declared, workgroup_bytes(tensor_cores), "{}", kernel.name);
        }
    }

    /// The fused pass against the host layer by layer: D/S's transfer network (51 → 172 →
    /// 172 → 64, f32 in, f16 out) and shading network (64 → 172 → 172 → 3, f16 in, f32 out),
    /// the baseline's five layers 256 wide, and eight layers (the most a pass holds), over row
    /// counts that are no multiple of a workgroup's 64 rows, within 1% of the largest output
    /// (f16 rounding; a bias read from the wrong layer or a column dropped misses by far more).
    /// The baseline's shape also holds the plain kernel to llvmpipe's 65,535 iterations of a
    /// loop: a term a k iteration ended its layers early and wrote zeros.
    #[test]
    fn a_fused_pass_computes_every_layer_of_the_mlp() {
        if !GpuDevice::probe() || !GpuDevice::get().unwrap().half {
            return;
        }
        for (widths, rows, half_in, half_out) in [
            (&[51, 172, 172, 64][..], 300, false, true),
            (&[64, 172, 172, 3][..], 100, true, false),
            (&[83, 256, 256, 256, 256, 3][..], 70, true, false),
            (&[16, 16, 32, 16, 48, 16, 16, 16, 7][..], 130, false, false),
        ] {
            let error = fused_error(widths, rows, half_in, half_out);
            eprintln!("{widths:?}: off by {error:.1e} of the largest output");
            assert!(
                error < 1e-2,
                "{widths:?}: off by {error} of the largest output"
            );
        }
    }

    /// A training step's fused pass (D/S's shading network, 64 → 172 → 172 → 3, f32 in and
    /// out, the first layer's bias a row per view as the light code's share makes it) keeps
    /// what backward reads, at the offsets it is given in shared buffers, against the host:
    /// the input as held f16 rows, each hidden layer's pre-activation (f32) and output (held
    /// f16 rows), zeros in the padding columns and past the rows (a weight's gradient sums
    /// over every held row), and the output; every value within 1% of its layer's largest, and
    /// nothing written outside its place.
    #[test]
    fn a_training_pass_keeps_what_backward_reads() {
        if !GpuDevice::probe() || !GpuDevice::get().unwrap().half {
            return;
        }
        let gpu = GpuDevice::get().unwrap();
        let (widths, rows, views) = ([64, 172, 172, 3], 300, 3);
        let mlp = Mlp::new(&gpu, &widths);
        let values: Vec<f32> = (0..rows * widths[0]).map(|i| value(i, 2.0)).collect();
        let x = gpu.upload(&values);
        let group: Vec<u32> = (0..rows as u32).map(|i| i * 7 % views).collect();
        let rows_of_bias: Vec<Vec<f32>> = (0..views as usize)
            .map(|v| (0..widths[1]).map(|j| value(j + 40 * v, 0.5)).collect())
            .collect();
        let bias0 = gpu.upload(&rows_of_bias.concat());
        let groups = gpu.upload(&group);
        // Places apart and not from zero, with a canary between them.
        let held_len = |w: usize| held_halves(rows, w);
        let input_at = 256;
        let first = input_at + held_len(64) + 256;
        let held_at = [first, first + held_len(172) + 256];
        let pre_at = [64, 64 + rows * 172 + 64];
        let (held_end, pre_end) = (
            held_at[1] + held_len(172) + 256,
            pre_at[1] + rows * 172 + 64,
        );
        let canary = -7.0;
        let held = gpu.upload(&vec![
            half::f16::from_f32(canary).to_bits();
            held_at[1] + held_len(172) + 256
        ]);
        let pre = gpu.upload(&vec![canary; pre_end]);
        let out = gpu.buffer(rows * 3);
        let kept = Kept {
            held: &held,
            pre: &pre,
            input_at,
            layers: vec![[held_at[0], pre_at[0]], [held_at[1], pre_at[1]]],
        };
        let layers = mlp.layers();
        let bias = Bias::Group(&bias0, &groups);
        let dispatch = half_mlp(
            &gpu,
            rows,
            (Held::F32(&x), 64),
            &layers,
            bias,
            &mlp.params,
            Held::F32(&out),
            Some(&kept),
        );
        gpu.submit([&dispatch]);
        let want = mlp.host_layers(&values, rows, &|i| rows_of_bias[group[i] as usize].clone());
        let input = held_rows(&gpu, &held, input_at, rows, 64);
        let want_input: Vec<f32> = padded(&values, rows, 64)
            .iter()
            .map(|&v| round16(v))
            .collect();
        let mut errors = vec![("input", relative(&input, &want_input))];
        let pre_got = gpu.read(&pre, pre_end);
        for l in 0..2 {
            let z = &pre_got[pre_at[l]..pre_at[l] + rows * 172];
            errors.push(("pre-activation", relative(z, &want[l][0])));
            let y = held_rows(&gpu, &held, held_at[l], rows, 172);
            errors.push((
                "hidden output",
                relative(&y, &padded(&want[l][1], rows, 172)),
            ));
        }
        errors.push(("output", relative(&gpu.read(&out, rows * 3), &want[2][1])));
        eprintln!("kept within {errors:?} of each one's largest value");
        for (what, error) in errors {
            assert!(error < 1e-2, "{what}: off by {error} of its largest value");
        }
        let bits = gpu.read(&held, held_end / 2);
        let bits: &[u16] = bytemuck::cast_slice(&bits);
        let outside = (0..bits.len()).filter(|&e| {
            let inside = |at: usize, len: usize| (at..at + len).contains(&e);
            !inside(input_at, held_len(64)) && !held_at.iter().any(|&a| inside(a, held_len(172)))
        });
        assert!(
            outside
                .clone()
                .all(|e| half::f16::from_bits(bits[e]).to_f32() == canary),
            "an f16 value written outside its place"
        );
        let pre_outside = (0..pre_got.len())
            .filter(|&e| !pre_at.iter().any(|&a| (a..a + rows * 172).contains(&e)));
        assert!(
            pre_outside.clone().all(|e| pre_got[e] == canary),
            "a pre-activation written outside its place"
        );
    }
}
