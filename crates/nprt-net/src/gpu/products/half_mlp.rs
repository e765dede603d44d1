//! A whole MLP's forward pass in half precision in one dispatch, for the frame path
//! (`half_mlp.wgsl`, after tiny-cuda-nn's fully fused MLP): a workgroup takes 64 rows through
//! every layer, their activations kept in workgroup memory between layers. Where the adapter
//! has cooperative matrices the products run on tensor cores (`half_mlp_coop`), elsewhere
//! without (`half_mlp_plain`). An MLP it cannot hold (a layer wider than 256 or more than 8
//! layers), or an adapter with less workgroup memory than it takes (32 KiB, 36 on tensor
//! cores), runs a layer a dispatch instead (`half_layers`).

use crate::gpu::kernels::{HALF_MLP_COOP, HALF_MLP_PLAIN};
use crate::gpu::products::half_layers::{pad16, HalfWeight, Held, HALF_ROW_BLOCK};
use nprt_gpu::{Bind, Dispatch, GpuDevice};

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

/// The dispatch of `layers` over `rows` rows of `x` into `y`: `x` f32 rows of `x_cols` values
/// (made f16 as they are read) or f16 rows of the first layer's padded width; `y` the last
/// layer's f32 rows of its width or f16 rows padded as [`Held::F16`] holds them. `bias0` is the
/// first layer's bias, `biases` the buffer the others' lie in. The layers must [`fits`].
pub fn half_mlp(
    gpu: &GpuDevice,
    rows: usize,
    (x, x_cols): (Held, usize),
    layers: &[FusedLayer],
    bias0: &dyn Bind,
    biases: &wgpu::Buffer,
    y: Held,
) -> Dispatch {
    assert!(fits(gpu, layers), "an MLP a fused pass cannot hold");
    let (x16, x32, x_f32) = match x {
        Held::F16(b) => (b, &gpu.empty, 0),
        Held::F32(b) => (&gpu.empty, b, 1),
    };
    let (y16, y32, half_out) = match y {
        Held::F16(b) => (b, &gpu.spare, 1),
        Held::F32(b) => (&gpu.spare, b, 0),
    };
    let mut params = vec![rows, layers.len(), x_f32, x_cols, half_out, 0, 0, 0];
    let mut shape = [[0; 4]; MAX_LAYERS];
    let mut at = [[0; 4]; MAX_LAYERS];
    for (i, l) in layers.iter().enumerate() {
        let w = l.weight;
        debug_assert_eq!(l.k_pad, pad16(l.k_pad));
        shape[i] = [l.k_pad, w.d_out, w.n_pad, l.activation as usize];
        at[i] = [w.offset, l.bias_at, 0, 0];
    }
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
        &[x16, x32, weights, bias0, biases, y16, y32],
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

    /// A fused pass over `rows` rows of an MLP `widths[0]` → … → `widths[last]` (ReLU, then
    /// linear), with weights and biases of a fixed pattern and the first layer's bias apart,
    /// against the same MLP on the host in f32 from the same f16 weights, each hidden output
    /// rounded to f16 as the pass holds it: the largest difference over the largest output.
    fn fused_error(widths: &[usize], rows: usize, half_in: bool, half_out: bool) -> f32 {
        let gpu = GpuDevice::get().unwrap();
        let shapes: Vec<[usize; 2]> = widths.windows(2).map(|w| [w[0], w[1]]).collect();
        let weights = gpu.half_weights(&shapes);
        let value = |i: usize, scale: f32| ((i * 7919 % 211) as f32 / 211.0 - 0.5) * scale;
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
            host.push((weight.iter().map(|&v| round16(v)).collect::<Vec<_>>(), bias));
        }
        let x: Vec<f32> = (0..rows * widths[0]).map(|i| value(i, 2.0)).collect();
        let k0 = pad16(widths[0]);
        let x_buffer = match half_in {
            true => {
                let mut bits = vec![0u16; held_halves(rows, widths[0])];
                for (i, row) in x.chunks(widths[0]).enumerate() {
                    for (k, &v) in row.iter().enumerate() {
                        bits[i * k0 + k] = half::f16::from_f32(v).to_bits();
                    }
                }
                gpu.upload(&bits)
            }
            false => gpu.upload(&x),
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
        let params = gpu.upload(&biases);
        let bias0 = gpu.upload(&host[0].1);
        let layers: Vec<FusedLayer> = (weights.iter().enumerate())
            .map(|(l, w)| FusedLayer {
                weight: w,
                k_pad: pad16(shapes[l][0]),
                bias_at: bias_at[l],
                activation: u32::from(l + 1 < shapes.len()),
            })
            .collect();
        let dispatch = half_mlp(&gpu, rows, (x_held, widths[0]), &layers, &bias0, &params, y);
        gpu.submit([&dispatch]);
        let got: Vec<f32> = match half_out {
            true => {
                let words = gpu.read(&out, held_halves(rows, last).div_ceil(2));
                let bits: &[u16] = bytemuck::cast_slice(&words);
                let n_pad = pad16(last);
                (0..rows * last)
                    .map(|e| half::f16::from_bits(bits[e / last * n_pad + e % last]).to_f32())
                    .collect()
            }
            false => gpu.read(&out, rows * last),
        };
        let mut want: Vec<f32> = x.iter().map(|&v| round16(v)).collect();
        for (l, (w, b)) in host.iter().enumerate() {
            let [d_in, d_out] = shapes[l];
            want = (0..rows * d_out)
                .map(|e| {
                    let (i, j) = (e / d_out, e % d_out);
                    let sum: f32 = (0..d_in)
                        .map(|k| want[i * d_in + k] * w[k * d_out + j])
                        .sum();
                    match l + 1 < shapes.len() {
                        true => round16((sum + b[j]).max(0.0)),
                        false => sum + b[j],
                    }
                })
                .collect();
        }
        let peak = want.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        let worst = (got.iter().zip(&want)).fold(0.0f32, |m, (g, w)| m.max((g - w).abs()));
        worst / peak
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
}
