//! The radiance cache on the GPU kernels: its weights, gradients and Adam's moments on the
//! device, read and trained with the kernels the designs use: the hash grid's lookup and its
//! gradient (`track_inputs`, `grid_backward`, over the queries' positions laid out as pixel
//! features), the MLP's products and backward pass, relative L2 (`radiance_loss`, the albedo as
//! the scale) and Adam. The rest of the input (the SH encodings, roughness, albedos) is encoded
//! on the host, as the CPU engine encodes it. It computes what `cpu::radiance_cache` computes.

use std::sync::Arc;

use anyhow::Result;
use glam::Vec3;

use crate::cpu::radiance_cache::encode_rest;
use crate::encoding::features::FEATURES;
use crate::encoding::hash_grid;
use crate::gpu::kernels::{RADIANCE_LOSS, TRACK_INPUTS};
use crate::gpu::layers::mlp_tape::MlpTape;
use crate::gpu::layers::network_forward::{FirstLayer, ForwardTargets};
use crate::gpu::layers::network_layout::{mlp_at, MlpAt};
use crate::gpu::layers::parameters::ParameterLayout;
use crate::gpu::passes::device_adam::DeviceAdam;
use crate::gpu::passes::grid_backward::{record_grid_backward, GridRows};
use crate::gpu::passes::mlp_step::Trainable;
use crate::gpu::products::codes::loss_code;
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::half_layers::Held;
use crate::gpu::products::operands::{Bias, Output};
use crate::gpu::trainers::plans::{submit, Pass, Plans};
use crate::loss::Loss;
use crate::network::radiance_cache::CacheSteps;
use crate::network::radiance_cache::{CacheQuery, RadianceCache, INPUTS};
use nprt_gpu::{groups_for, Dispatch, GpuDevice, Part, Span};

/// Rows a read records at once.
const READ_ROWS: usize = 4096;

/// A pass over `rows` queries, recorded once per row count: its buffers and dispatches.
struct CachePlan {
    rows: usize,
    features: wgpu::Buffer,
    x: wgpu::Buffer,
    albedo: wgpu::Buffer,
    targets: wgpu::Buffer,
    tape: MlpTape,
    loss: wgpu::Buffer,
    dispatches: Vec<Dispatch>,
    /// The forward pass's dispatches (the rest make the loss and every gradient).
    forward: usize,
}

/// The cache's weights on the device and its passes.
pub struct GpuCache {
    gpu: Arc<GpuDevice>,
    layout: ParameterLayout,
    grid: Span,
    mlp: MlpAt,
    shapes: RadianceCache,
    params: wgpu::Buffer,
    grads: wgpu::Buffer,
    adam: DeviceAdam,
    resolutions: wgpu::Buffer,
    /// The passes of the last row counts used.
    plans: Plans<CachePlan>,
}

impl GpuCache {
    /// Uploads `cache`'s weights to the process's GPU device, with zero Adam moments under the
    /// cache's decay rates.
    pub fn new(cache: &RadianceCache, betas: [f32; 2]) -> Result<Self> {
        let gpu = GpuDevice::get()?;
        let (layout, flat) = ParameterLayout::pack_for(&gpu, cache);
        let params = gpu.upload(&flat);
        let grads = gpu.buffer(layout.total);
        // Spans in the cache's visiting order: the grid's table, then the MLP's layers.
        let mut spans = layout.spans.iter().copied();
        let grid = spans.next().expect("the grid's span");
        let mlp = mlp_at(&cache.mlp, &mut spans);
        Ok(GpuCache {
            adam: DeviceAdam::with_betas(&gpu, layout.total, &grads, &params, betas),
            resolutions: gpu.upload(&hash_grid::resolutions()),
            shapes: cache.clone(),
            plans: Plans::default(),
            grid,
            mlp,
            params,
            grads,
            layout,
            gpu,
        })
    }

    /// The weights' current values.
    pub fn parameters(&self) -> RadianceCache {
        let flat = self.gpu.read(&self.params, self.layout.total);
        self.layout.unpack(&flat, &self.shapes)
    }

    /// The radiance the cache holds for each query.
    pub fn read(&mut self, queries: &[CacheQuery]) -> Vec<Vec3> {
        let mut out = Vec::with_capacity(queries.len());
        for chunk in queries.chunks(READ_ROWS) {
            self.upload(chunk, None);
            self.submit(Pass::Forward);
            let plan = self.plans.last().expect("uploaded");
            let y = self.gpu.read(&plan.tape.output, 3 * chunk.len());
            let radiance = (chunk.iter().zip(y.chunks_exact(3)))
                .map(|(q, o)| Vec3::from_slice(o) * q.albedo());
            out.extend(radiance);
        }
        out
    }

    /// One Adam step at `lr` on the queries' relative L2 loss against `targets`; returns the
    /// loss.
    pub fn step(&mut self, queries: &[CacheQuery], targets: &[Vec3], lr: f64) -> f64 {
        self.upload(queries, Some(targets));
        self.submit(Pass::Step(lr));
        let plan = self.plans.last().expect("uploaded");
        self.gpu.read(&plan.loss, 1)[0] as f64 / (3 * queries.len()).max(1) as f64
    }

    /// The loss of the queries against `targets` and every weight's gradient, as
    /// `RadianceCache::loss_and_gradients` makes them (for the tests).
    pub fn loss_and_gradients(
        &mut self,
        queries: &[CacheQuery],
        targets: &[Vec3],
    ) -> (f64, RadianceCache) {
        self.upload(queries, Some(targets));
        self.submit(Pass::Backward);
        let plan = self.plans.last().expect("uploaded");
        let loss = self.gpu.read(&plan.loss, 1)[0] as f64 / (3 * queries.len()).max(1) as f64;
        let flat = self.gpu.read(&self.grads, self.layout.total);
        (loss, self.layout.unpack(&flat, &self.shapes))
    }

    /// Makes the plan for `queries.len()` rows the last (recorded unless kept) and writes the
    /// queries, and `targets` where given, into its buffers.
    fn upload(&mut self, queries: &[CacheQuery], targets: Option<&[Vec3]>) {
        let rows = queries.len();
        let plan = match self.plans.take(|p| p.rows == rows) {
            Some(plan) => plan,
            None => self.record(rows),
        };
        let mut features = vec![0.0f32; rows * FEATURES];
        for (q, f) in queries.iter().zip(features.chunks_exact_mut(FEATURES)) {
            f[..3].copy_from_slice(&q.position);
        }
        let mut x = vec![0.0f32; rows * INPUTS];
        encode_rest(queries, &mut x);
        let albedo: Vec<f32> = queries.iter().flat_map(|q| q.albedo().to_array()).collect();
        self.gpu.write(&plan.features, &features);
        self.gpu.write(&plan.x, &x);
        self.gpu.write(&plan.albedo, &albedo);
        if let Some(t) = targets {
            let t: Vec<f32> = t.iter().flat_map(|v| v.to_array()).collect();
            self.gpu.write(&plan.targets, &t);
        }
        self.plans.keep(plan);
    }

    /// Runs what `pass` asks of the last plan.
    fn submit(&mut self, pass: Pass) {
        let plan = self.plans.last().expect("uploaded");
        let recorded = (plan.dispatches.as_slice(), plan.forward);
        submit(
            &self.gpu,
            recorded,
            pass,
            (&mut self.adam, self.layout.total),
        );
    }

    /// Records a pass over `rows` queries: the grid's encoding into the input's first columns,
    /// the MLP; then relative L2 against the targets (the albedo as the output's scale) and
    /// backward into every gradient.
    fn record(&self, rows: usize) -> CachePlan {
        let gpu = &self.gpu;
        let t = Trainable {
            gpu,
            params: &self.params,
            grads: &self.grads,
        };
        let (features, x) = (gpu.buffer(rows * FEATURES), gpu.buffer(rows * INPUTS));
        let (albedo, targets) = (gpu.buffer(rows * 3), gpu.buffer(rows * 3));
        let table = Part {
            buffer: &self.params,
            span: self.grid,
        };
        let mut dispatches = vec![gpu.prepare(
            &TRACK_INPUTS,
            &[rows, 0, INPUTS, 1].map(|v| v as u32),
            &[&features, &gpu.empty, &table, &self.resolutions, &x],
            groups_for(rows),
        )];
        let tape = MlpTape::new(t.gpu, &self.mlp, rows);
        let first = FirstLayer {
            own_row: 0,
            count: INPUTS,
            bias: Bias::Column(&self.params, self.mlp.layers[0].bias.offset),
        };
        let to = ForwardTargets::Tape(&tape);
        let input = Held::F32(&x);
        (self.mlp).record_forward(gpu, &mut dispatches, &self.params, input, rows, first, &to);
        let forward = dispatches.len();
        let (d_out, row_loss, loss) = (gpu.buffer(rows * 3), gpu.buffer(rows), gpu.buffer(1));
        let mut p = vec![rows as u32, loss_code(Loss::RelL2), 0, 0];
        p.extend([1.0 / (3 * rows.max(1)) as f32, 0.0, 0.0, 0.0].map(f32::to_bits));
        let y = &tape.output;
        dispatches.push(gpu.prepare(
            &RADIANCE_LOSS,
            &p,
            &[y, &targets, &albedo, &d_out, &row_loss],
            groups_for(rows),
        ));
        gpu.column_sum(
            &mut dispatches,
            &row_loss,
            rows,
            1,
            None,
            Output::to(&loss, 0, 1),
        );
        let dx = gpu.buffer(rows * INPUTS);
        let input = (&x, 0, INPUTS);
        t.mlp_backward(
            &mut dispatches,
            &self.mlp,
            &tape,
            input,
            &d_out,
            Some(&dx),
            None,
        );
        let at = GridRows {
            features: &features,
            rows,
            count: 0,
            width: INPUTS,
        };
        let buffers = [&self.resolutions, &dx, &self.grads];
        record_grid_backward(gpu, &mut dispatches, at, buffers, self.grid);
        CachePlan {
            rows,
            features,
            x,
            albedo,
            targets,
            tape,
            loss,
            dispatches,
            forward,
        }
    }
}

impl CacheSteps for GpuCache {
    fn cache(&self) -> RadianceCache {
        self.parameters()
    }

    fn read(&mut self, queries: &[CacheQuery]) -> Vec<Vec3> {
        GpuCache::read(self, queries)
    }

    fn step(&mut self, queries: &[CacheQuery], targets: &[Vec3], lr: f64) -> f64 {
        GpuCache::step(self, queries, targets, lr)
    }
}
