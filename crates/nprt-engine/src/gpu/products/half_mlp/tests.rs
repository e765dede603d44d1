//! The fused MLP kernels against the host: each pass on f16 rows within f16's rounding.

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
    transposed: Vec<HalfWeight>,
    host: Vec<(Vec<f32>, Vec<f32>)>,
    params: wgpu::Buffer,
    bias_at: Vec<usize>,
}

impl Mlp {
    fn new(gpu: &GpuDevice, widths: &[usize]) -> Self {
        let shapes: Vec<[usize; 2]> = widths.windows(2).map(|w| [w[0], w[1]]).collect();
        let weights = gpu.half_weights(&shapes);
        let flipped: Vec<[usize; 2]> = shapes.iter().map(|&[i, o]| [o, i]).collect();
        let transposed = gpu.half_weights(&flipped);
        let mut host = Vec::new();
        let mut biases = vec![0.0; 64];
        let mut bias_at = Vec::new();
        for (l, (&[d_in, d_out], w)) in shapes.iter().zip(&weights).enumerate() {
            let scale = 2.0 / (d_in as f32).sqrt();
            let weight: Vec<f32> = (0..d_in * d_out).map(|i| value(i + l, scale)).collect();
            let bits = half_weight_bits(&weight, d_in, d_out);
            gpu.queue
                .write_buffer(&w.buffer, 2 * w.offset as u64, bytemuck::cast_slice(&bits));
            let t = &transposed[l];
            let flip: Vec<f32> = (0..d_in * d_out)
                .map(|e| weight[e % d_in * d_out + e / d_in])
                .collect();
            let bits = half_weight_bits(&flip, d_out, d_in);
            gpu.queue
                .write_buffer(&t.buffer, 2 * t.offset as u64, bytemuck::cast_slice(&bits));
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
            transposed,
            host,
            params,
            bias_at,
        }
    }

    /// The forward pass's layers, the hidden ones' places in a tape from `kept`.
    fn layers(&self, kept: &[[usize; 2]]) -> Vec<FusedLayer<'_>> {
        (self.weights.iter().enumerate())
            .map(|(l, w)| {
                let [held_at, pre_at] = kept.get(l).copied().unwrap_or_default();
                FusedLayer {
                    weight: w,
                    k_pad: pad16(self.shapes[l][0]),
                    bias_at: self.bias_at[l],
                    activation: u32::from(l + 1 < self.shapes.len()),
                    held_at,
                    pre_at,
                }
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
    let bias0 = gpu.upload(&mlp.host[0].1);
    let io = FusedIo {
        rows,
        x: x_held,
        x_cols: widths[0],
        bias0: Bias::Column(&bias0, 0),
        biases: Some(&mlp.params),
        y16: half_out.then_some(&out),
        out16: half_out,
        kept_input: None,
        y32: (!half_out).then_some(&out),
        pre: None,
    };
    gpu.submit([&half_mlp(&gpu, &mlp.layers(&[]), &io)]);
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
    let held = gpu.upload(&vec![half::f16::from_f32(canary).to_bits(); held_end]);
    let pre = gpu.upload(&vec![canary; pre_end]);
    let out = gpu.buffer(rows * 3);
    let kept = [[held_at[0], pre_at[0]], [held_at[1], pre_at[1]]];
    let io = FusedIo {
        rows,
        x: Held::F32(&x),
        x_cols: 64,
        bias0: Bias::Group(&bias0, &groups),
        biases: Some(&mlp.params),
        y16: Some(&held),
        out16: false,
        kept_input: Some(input_at),
        y32: Some(&out),
        pre: Some((&pre, Pre::Keep)),
    };
    gpu.submit([&half_mlp(&gpu, &mlp.layers(&kept), &io)]);
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
    let pre_outside =
        (0..pre_got.len()).filter(|&e| !pre_at.iter().any(|&a| (a..a + rows * 172).contains(&e)));
    assert!(
        pre_outside.clone().all(|e| pre_got[e] == canary),
        "a pre-activation written outside its place"
    );
}

/// A training step's fused backward pass (`half_products`' input gradients: D/S's shading
/// network, 64 → 172 → 172 → 3, from the last layer down to the first's output, on the
/// transposed weights) against the host: the gradient at the output kept as held f16
/// rows, each layer's gradient at its pre-activation (times ReLU's derivative at the
/// pre-activations the forward pass kept) as held f16 rows, the first layer's as f32 rows
/// too, each within 1% of its largest value; nothing written outside its place, and the
/// pre-activations unchanged. Then again on to the first layer's input (one more stage,
/// linear): the input's gradient as f32 rows in place of the first layer's.
#[test]
fn a_backward_pass_keeps_every_layers_gradient() {
    if !GpuDevice::probe() || !GpuDevice::get().unwrap().half {
        return;
    }
    let gpu = GpuDevice::get().unwrap();
    let (widths, rows) = ([64, 172, 172, 3], 300);
    let mlp = Mlp::new(&gpu, &widths);
    let values: Vec<f32> = (0..rows * widths[0]).map(|i| value(i, 2.0)).collect();
    let forward = mlp.host_layers(&values, rows, &|_| mlp.host[0].1.clone());
    let d_last: Vec<f32> = (0..rows * 3).map(|i| value(i + 5, 0.5)).collect();
    let canary = -7.0;
    // The pre-activations where the forward pass keeps them, canaries around them.
    let pre_at = [64, 64 + rows * 172 + 64];
    let mut pre_values = vec![canary; pre_at[1] + rows * 172 + 64];
    for l in 0..2 {
        pre_values[pre_at[l]..pre_at[l] + rows * 172].copy_from_slice(&forward[l][0]);
    }
    // The gradients' places: at the output, then at layers 1 and 0.
    let held_len = |w: usize| held_halves(rows, w);
    let out_at = 256;
    let at1 = out_at + held_len(3) + 256;
    let at0 = at1 + held_len(172) + 256;
    let held_end = at0 + held_len(172) + 256;
    let stage = |l: usize, held_at: usize| FusedLayer {
        weight: &mlp.transposed[l],
        k_pad: pad16(widths[l + 1]),
        bias_at: 0,
        activation: if l > 0 { 3 } else { 0 },
        held_at,
        pre_at: if l > 0 { pre_at[l - 1] } else { 0 },
    };
    // The host's: each gradient from the one above as f16, times Wᵀ, times ReLU' but at
    // the input.
    let back = |g: &[f32], l: usize| -> Vec<f32> {
        let [d_in, d_out] = mlp.shapes[l];
        let w = &mlp.host[l].0;
        (0..rows * d_in)
            .map(|e| {
                let (i, k) = (e / d_in, e % d_in);
                let sum: f32 = (0..d_out)
                    .map(|j| g[i * d_out + j] * w[k * d_out + j])
                    .sum();
                match l == 0 || forward[l - 1][0][e] > 0.0 {
                    true => sum,
                    false => 0.0,
                }
            })
            .collect()
    };
    let round = |v: &[f32]| v.iter().map(|&v| round16(v)).collect::<Vec<_>>();
    let g2 = round(&d_last);
    let g1 = back(&g2, 2);
    let g0 = back(&round(&g1), 1);
    let d_input = back(&round(&g0), 0);
    for to_input in [false, true] {
        let pre = gpu.upload(&pre_values);
        let held = gpu.upload(&vec![half::f16::from_f32(canary).to_bits(); held_end]);
        let y32 = gpu.buffer(rows * if to_input { 64 } else { 172 });
        let mut stages = vec![stage(2, at1), stage(1, at0)];
        if to_input {
            stages.push(stage(0, 0));
        }
        let io = FusedIo {
            rows,
            x: Held::F32(&gpu.upload(&d_last)),
            x_cols: 3,
            bias0: Bias::None,
            biases: None,
            y16: Some(&held),
            out16: !to_input,
            kept_input: Some(out_at),
            y32: Some(&y32),
            pre: Some((&pre, Pre::Derive)),
        };
        gpu.submit([&half_mlp(&gpu, &stages, &io)]);
        let mut errors = vec![
            (
                "output's",
                relative(
                    &held_rows(&gpu, &held, out_at, rows, 3),
                    &padded(&g2, rows, 3),
                ),
            ),
            (
                "layer 1's",
                relative(
                    &held_rows(&gpu, &held, at1, rows, 172),
                    &padded(&round(&g1), rows, 172),
                ),
            ),
            (
                "layer 0's",
                relative(
                    &held_rows(&gpu, &held, at0, rows, 172),
                    &padded(&round(&g0), rows, 172),
                ),
            ),
        ];
        errors.push(match to_input {
            true => ("input's", relative(&gpu.read(&y32, rows * 64), &d_input)),
            false => ("layer 0's f32", relative(&gpu.read(&y32, rows * 172), &g0)),
        });
        eprintln!("to the input {to_input}: gradients within {errors:?} of each one's largest");
        for (what, error) in errors {
            assert!(
                error < 1e-2,
                "to the input {to_input}: the {what} gradient off by {error} of its largest"
            );
        }
        let words = gpu.read(&held, held_end / 2);
        let bits: &[u16] = bytemuck::cast_slice(&words);
        let places = [
            (out_at, held_len(3)),
            (at1, held_len(172)),
            (at0, held_len(172)),
        ];
        let outside =
            (0..held_end).filter(|&e| !places.iter().any(|&(a, n)| (a..a + n).contains(&e)));
        assert!(
            outside
                .clone()
                .all(|e| half::f16::from_bits(bits[e]).to_f32() == canary),
            "an f16 value written outside its place"
        );
        assert_eq!(
            gpu.read(&pre, pre_values.len()),
            pre_values,
            "to the input {to_input}: the pre-activations changed"
        );
    }
}
