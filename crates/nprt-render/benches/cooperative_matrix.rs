//! Which product the frame path's tensor-core kernel uses (`half_dense_coop`): C = A·B with A
//! and B f16, C f32, on wgpu's cooperative matrices (16 × 16 × 16 f16 products into f32),
//! with four subgroups of 32 a workgroup, each computing TM × TN tiles, read straight from
//! storage or staged through workgroup memory first (from f16, or from f32 converted), at a
//! square size and at the frame's shapes (262,144 rows, 256 and 192 wide). Then the two other
//! products a training step on tensor cores would run (docs/model.md, "Not yet done"), read
//! straight from storage: a layer's input gradient dz·Wᵀ, W read as stored (d_in × d_out) by
//! column-major loads; and its weight gradient xᵀ·dz over a batch of 262,144 rows, x read as
//! stored (rows × d_in) by column-major loads and the rows split into 32 chunks, each
//! workgroup's sum written apart for a column sum to add. Each variant's result is checked
//! against the host at a few entries. Prints the adapter's cooperative matrix configurations
//! first; where it has none, it stops there.
//!
//! cargo bench -p nprt-render --features gpu --bench cooperative_matrix [-- --validate]
//!
//! `--validate` only checks each variant's WGSL with naga and translates it to SPIR-V, which
//! needs no GPU. On one H200 (driver 580.159.04, 2026-11-26), straight from storage, 4 × 4 tiles
//! a subgroup ran 75.7 TFLOP/s at 4096³ and 59.6 at 262,144 × 256 × 256 (2 × 2: 38.3 and 35.1);
//! staged through workgroup memory, 9.8–18.4; at 262,144 × 192 × 192 the best was 23.5
//! (docs/export.md, "Half precision"). The training products have not yet run on a GPU.

use std::time::Instant;

use wgpu::util::DeviceExt;

/// How a product's operands are stored: A as m × k row-major, or (`a_t`) as its transpose,
/// k × m; B as k × n, or (`b_t`) n × k; and the chunks k is split into, each chunk's C written
/// apart (`chunks` × m × n).
#[derive(Clone, Copy)]
struct Layout {
    a_t: bool,
    b_t: bool,
    chunks: usize,
}

const PLAIN: Layout = Layout {
    a_t: false,
    b_t: false,
    chunks: 1,
};

/// `src`: "direct" (coopLoad from f16 storage), "f16" (staged from f16 storage), "f32" (staged
/// from f32 storage, converted); staged variants take the plain layout only.
fn shader(tm: usize, tn: usize, src: &str, layout: Layout) -> String {
    let wm = 2 * tm * 16;
    let wn = 2 * tn * 16;
    let staged = src != "direct";
    let mut s = String::from(
        "enable f16;\nenable wgpu_cooperative_matrix;\n\
         @group(0) @binding(0) var<storage, read> a: array<f16>;\n\
         @group(0) @binding(1) var<storage, read> b: array<f16>;\n\
         @group(0) @binding(2) var<storage, read_write> c: array<f32>;\n\
         struct P { m: u32, n: u32, k: u32, kc: u32 }\n\
         @group(0) @binding(3) var<uniform> p: P;\n\
         @group(0) @binding(4) var<storage, read> af: array<f32>;\n\
         @group(0) @binding(5) var<storage, read> bf: array<f32>;\n",
    );
    if staged {
        s += &format!(
            "var<workgroup> sa: array<f16, {}>;\nvar<workgroup> sb: array<f16, {}>;\n",
            wm * 32,
            32 * wn
        );
    }
    s += "@compute @workgroup_size(128)\nfn main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) li: u32) {\n";
    s += "  let sg = li / 32u;\n  let ldc = p.n;\n  let c0 = wg.z * p.m * p.n;\n";
    s += &format!("  let row0 = wg.y * {wm}u + (sg / 2u) * {}u;\n  let col0 = wg.x * {wn}u + (sg % 2u) * {}u;\n", tm * 16, tn * 16);
    s += &format!(
        "  let lr0 = (sg / 2u) * {}u;\n  let lc0 = (sg % 2u) * {}u;\n",
        tm * 16,
        tn * 16
    );
    for i in 0..tm {
        for j in 0..tn {
            s += &format!("  var c{i}{j} = coop_mat16x16<f32, C>();\n");
        }
    }
    let kstep = if staged { 32 } else { 16 };
    s += &format!("  for (var k = wg.z * p.kc; k < (wg.z + 1u) * p.kc; k += {kstep}u) {{\n");
    if staged {
        let (ra, rb) = if src == "f32" {
            ("f16(af", "f16(bf")
        } else {
            ("(a", "(b")
        };
        s += &format!("    for (var e = li; e < {}u; e += 128u) {{ let r = e / 32u; let q = e % 32u; sa[e] = {ra}[(wg.y * {wm}u + r) * p.k + k + q]); }}\n", wm * 32);
        s += &format!("    for (var e = li; e < {}u; e += 128u) {{ let r = e / {wn}u; let q = e % {wn}u; sb[e] = {rb}[(k + r) * p.n + wg.x * {wn}u + q]); }}\n", 32 * wn);
        s += "    workgroupBarrier();\n";
        for kk in 0..2 {
            for i in 0..tm {
                s += &format!("    let a{kk}{i} = coopLoadT<coop_mat16x16<f16, A>>(&sa[(lr0 + {}u) * 32u + {}u], 32u);\n", i * 16, kk * 16);
            }
            for j in 0..tn {
                s += &format!("    let b{kk}{j} = coopLoadT<coop_mat16x16<f16, B>>(&sb[{}u * {wn}u + lc0 + {}u], {wn}u);\n", kk * 16, j * 16);
            }
            for i in 0..tm {
                for j in 0..tn {
                    s += &format!("    c{i}{j} = coopMultiplyAdd(a{kk}{i}, b{kk}{j}, c{i}{j});\n");
                }
            }
        }
        s += "    workgroupBarrier();\n";
    } else {
        // coopLoadT reads a row-major tile, coopLoad a column-major one: a transposed operand
        // is its stored matrix's tile read column-major.
        for i in 0..tm {
            s += &match layout.a_t {
                false => format!("    let a{i} = coopLoadT<coop_mat16x16<f16, A>>(&a[(row0 + {}u) * p.k + k], p.k);\n", i * 16),
                true => format!("    let a{i} = coopLoad<coop_mat16x16<f16, A>>(&a[k * p.m + row0 + {}u], p.m);\n", i * 16),
            };
        }
        for j in 0..tn {
            s += &match layout.b_t {
                false => format!("    let b{j} = coopLoadT<coop_mat16x16<f16, B>>(&b[k * p.n + col0 + {}u], p.n);\n", j * 16),
                true => format!("    let b{j} = coopLoad<coop_mat16x16<f16, B>>(&b[(col0 + {}u) * p.k + k], p.k);\n", j * 16),
            };
        }
        for i in 0..tm {
            for j in 0..tn {
                s += &format!("    c{i}{j} = coopMultiplyAdd(a{i}, b{j}, c{i}{j});\n");
            }
        }
    }
    s += "  }\n";
    // Every binding used, so that one layout serves all variants.
    s += "  let keep = af[0] + bf[0] + f32(a[0]) + f32(b[0]);\n  if (keep == 12345.0) { c[0] = 0.0; }\n";
    for i in 0..tm {
        for j in 0..tn {
            // naga 30's SPIR-V writer needs the stored matrix and the offset bound by `let`.
            s += &format!("  let r{i}{j} = c{i}{j};\n  let o{i}{j} = c0 + (row0 + {}u) * ldc + col0 + {}u;\n  coopStoreT(r{i}{j}, &c[o{i}{j}], ldc);\n", i * 16, j * 16);
        }
    }
    s += "}\n";
    s
}

const VARIANTS: [(usize, usize, &str); 7] = [
    (2, 2, "direct"),
    (4, 2, "direct"),
    (4, 4, "direct"),
    (2, 2, "f16"),
    (4, 2, "f16"),
    (4, 2, "f32"),
    (4, 4, "f32"),
];

/// A training step's products on tensor cores: the name, the layout, and C's shapes
/// `[m, n, k]`.
const TRAINING: [(&str, Layout, [[usize; 3]; 2]); 2] = [
    (
        "dz·Wt",
        Layout {
            a_t: false,
            b_t: true,
            chunks: 1,
        },
        [[262_144, 256, 256], [262_144, 192, 192]],
    ),
    (
        "xt·dz",
        Layout {
            a_t: true,
            b_t: false,
            chunks: 32,
        },
        [[256, 256, 262_144], [192, 192, 262_144]],
    ),
];

fn main() {
    let direct = [(2, 2), (4, 2), (4, 4)];
    if std::env::args().any(|a| a == "--validate") {
        for (tm, tn, v) in VARIANTS {
            let words = spirv_words(&shader(tm, tn, v, PLAIN));
            println!("{tm}x{tn} {v}: valid, {words} SPIR-V words");
        }
        for (name, layout, _) in TRAINING {
            for (tm, tn) in direct {
                let words = spirv_words(&shader(tm, tn, "direct", layout));
                println!("{name} {tm}x{tn}: valid, {words} SPIR-V words");
            }
        }
        return;
    }
    let Some((device, queue)) = open_device() else {
        return;
    };
    let fits = |[m, n]: [usize; 2], tm: usize, tn: usize| m % (32 * tm) == 0 && n % (32 * tn) == 0;
    for [m, n, k] in [[4096, 4096, 4096], [262_144, 256, 256], [262_144, 192, 192]] {
        let product = Product::new(&device, [m, n, k], PLAIN);
        for (tm, tn, v) in VARIANTS
            .into_iter()
            .filter(|&(tm, tn, _)| fits([m, n], tm, tn))
        {
            let result = product.time(&device, &queue, &shader(tm, tn, v, PLAIN), [tm, tn]);
            report(&format!("{m}x{n}x{k} {tm}x{tn} {v}"), [m, n, k], result);
        }
    }
    for (name, layout, shapes) in TRAINING {
        for [m, n, k] in shapes {
            let product = Product::new(&device, [m, n, k], layout);
            for (tm, tn) in direct.into_iter().filter(|&(tm, tn)| fits([m, n], tm, tn)) {
                let wgsl = shader(tm, tn, "direct", layout);
                let result = product.time(&device, &queue, &wgsl, [tm, tn]);
                let chunks = layout.chunks;
                report(
                    &format!("{name} {m}x{n}x{k} ({chunks} chunks of k) {tm}x{tn}"),
                    [m, n, k],
                    result,
                );
            }
        }
    }
}

/// One variant's line: its time and rate, or why it did not run.
fn report(what: &str, [m, n, k]: [usize; 3], result: Result<(f64, f32), String>) {
    match result {
        Ok((ms, worst)) => println!(
            "{what}: {ms:.3} ms, {:.1} TFLOP/s, worst error {worst}",
            2.0 * (m * n * k) as f64 / ms / 1e9
        ),
        Err(e) => println!("{what}: {e}"),
    }
}

/// The variant's WGSL validated by naga and translated to SPIR-V: its length in words.
fn spirv_words(wgsl: &str) -> usize {
    let module = naga::front::wgsl::parse_str(wgsl)
        .unwrap_or_else(|e| panic!("{}\n{wgsl}", e.emit_to_string(wgsl)));
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}\n{wgsl}", e.emit_to_string(wgsl)));
    naga::back::spv::write_vec(&module, &info, &Default::default(), None)
        .expect("SPIR-V")
        .len()
}

/// The first high-performance adapter's device with f16 cooperative matrices, after printing
/// what the adapter offers; None where it has none.
fn open_device() -> Option<(wgpu::Device, wgpu::Queue)> {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::PRIMARY;
    let instance = wgpu::Instance::new(desc);
    let options = wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    };
    let adapter = futures_lite::future::block_on(instance.request_adapter(&options)).ok()?;
    let info = adapter.get_info();
    println!(
        "adapter: {} ({}, {:?})",
        info.name, info.driver_info, info.backend
    );
    for c in adapter.cooperative_matrix_properties() {
        println!("cooperative matrix: {c:?}");
    }
    let need = wgpu::Features::EXPERIMENTAL_COOPERATIVE_MATRIX | wgpu::Features::SHADER_F16;
    if !adapter.features().contains(need) {
        println!("no f16 cooperative matrices on this adapter");
        return None;
    }
    let descriptor = wgpu::DeviceDescriptor {
        label: None,
        required_features: need,
        required_limits: adapter.limits(),
        // SAFETY: the variants use cooperative matrices as naga validates them.
        experimental_features: unsafe { wgpu::ExperimentalFeatures::enabled() },
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    };
    futures_lite::future::block_on(adapter.request_device(&descriptor)).ok()
}

/// One product's operands on the device as `layout` stores them (f16 and f32 copies), its
/// output (a block per chunk of k) and its readback.
struct Product {
    shape: [usize; 3],
    layout: Layout,
    host: [Vec<f32>; 2],
    buffers: [wgpu::Buffer; 6],
    read: wgpu::Buffer,
}

impl Product {
    fn new(device: &wgpu::Device, [m, n, k]: [usize; 3], layout: Layout) -> Self {
        // Multiples of 1/8 in [-1, 1]: exact in f16, so every variant's sums are exact too.
        let mut seed = 1u32;
        let mut values = |count: usize| -> Vec<f32> {
            (0..count)
                .map(|_| {
                    seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                    ((seed >> 16) % 17) as f32 / 8.0 - 1.0
                })
                .collect()
        };
        let host = [values(m * k), values(k * n)];
        let init = |data: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents: data,
                usage,
            })
        };
        let half = |v: &[f32]| -> Vec<u16> {
            v.iter()
                .map(|&x| half::f16::from_f32(x).to_bits())
                .collect()
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let bytes = (layout.chunks * m * n * 4) as u64;
        let output = |usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: bytes,
                usage,
                mapped_at_creation: false,
            })
        };
        let buffers = [
            init(bytemuck::cast_slice(&half(&host[0])), storage),
            init(bytemuck::cast_slice(&half(&host[1])), storage),
            output(storage | wgpu::BufferUsages::COPY_SRC),
            init(
                bytemuck::cast_slice(&[m, n, k, k / layout.chunks].map(|v| v as u32)),
                wgpu::BufferUsages::UNIFORM,
            ),
            init(bytemuck::cast_slice(&host[0]), storage),
            init(bytemuck::cast_slice(&host[1]), storage),
        ];
        let read = output(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        Product {
            shape: [m, n, k],
            layout,
            host,
            buffers,
            read,
        }
    }

    /// Milliseconds per product of `wgsl` (each subgroup TM × TN tiles): the mean of 20 in one
    /// submission, after 2 untimed, and the largest error at five entries.
    fn time(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        wgsl: &str,
        [tm, tn]: [usize; 2],
    ) -> Result<(f64, f32), String> {
        let [m, n, k] = self.shape;
        let chunks = self.layout.chunks;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: None,
            source: wgpu::ShaderSource::Wgsl(wgsl.into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: None,
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        if let Some(e) = futures_lite::future::block_on(scope.pop()) {
            return Err(format!("pipeline refused: {e}"));
        }
        let entries: Vec<_> = (0..)
            .zip(&self.buffers)
            .map(|(binding, b)| wgpu::BindGroupEntry {
                binding,
                resource: b.as_entire_binding(),
            })
            .collect();
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        let run = |reps: usize| {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &group, &[]);
                for _ in 0..reps {
                    let groups = [n / (32 * tn), m / (32 * tm), chunks].map(|v| v as u32);
                    pass.dispatch_workgroups(groups[0], groups[1], groups[2]);
                }
            }
            queue.submit([encoder.finish()]);
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .expect("GPU");
        };
        run(2);
        let clock = Instant::now();
        run(20);
        let ms = clock.elapsed().as_secs_f64() * 1e3 / 20.0;
        let mut encoder = device.create_command_encoder(&Default::default());
        let bytes = (chunks * m * n * 4) as u64;
        encoder.copy_buffer_to_buffer(&self.buffers[2], 0, &self.read, 0, bytes);
        queue.submit([encoder.finish()]);
        self.read.slice(..).map_async(wgpu::MapMode::Read, |_| {});
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("GPU");
        let got: Vec<f32> = {
            let view = self.read.slice(..).get_mapped_range().expect("mapped");
            bytemuck::cast_slice(&view[..]).to_vec()
        };
        self.read.unmap();
        let [a, b] = &self.host;
        let Layout { a_t, b_t, .. } = self.layout;
        let a_at = |i: usize, l: usize| if a_t { a[l * m + i] } else { a[i * k + l] };
        let b_at = |l: usize, j: usize| if b_t { b[j * k + l] } else { b[l * n + j] };
        let worst = [
            (0, 0),
            (17, 101),
            (m - 1, n - 1),
            (1234 % m, 77),
            (m / 2, n / 3),
        ]
        .iter()
        .map(|&(i, j)| {
            let want: f32 = (0..k).map(|l| a_at(i, l) * b_at(l, j)).sum();
            let sum: f32 = (0..chunks).map(|c| got[(c * m + i) * n + j]).sum();
            (sum - want).abs()
        })
        .fold(0.0, f32::max);
        Ok((ms, worst))
    }
}
