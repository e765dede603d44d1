//! A design's training step on the GPU: the light encoder's and the transport networks'
//! forward passes keeping what backward needs, the loss and its gradient, backward into every
//! parameter's gradient, and one Adam step over all parameters, recorded as one queue
//! submission of our own kernels (a handful of dispatches per layer) with no host round trip
//! inside it.
//!
//! It computes what the CPU engine computes, in f32, and the tests hold the two together; Adam
//! is the host's ([`crate::optimiser::Adam`]), with the same state file. In [`Precision::F16`] the transport networks' dense layers run in mixed precision
//! (`half_products`), the master weights and Adam staying f32.

use std::path::Path;
use std::sync::Arc;

use anyhow::Result;

use crate::cpu::Samples;
use crate::encoding::features::FEATURES;
use crate::encoding::hash_grid;
use crate::gpu::kernels::GATHER_SAMPLES;
use crate::gpu::layers::network_layout::{LightAt, NetworkLayout};
use crate::gpu::layers::parameters::ParameterLayout;
use crate::gpu::passes::device_adam::DeviceAdam;
use crate::gpu::passes::mlp_step::Trainable;
use crate::gpu::trainers::device_dataset::DeviceDataset;
use crate::gpu::trainers::plans::{Pass, Plans};
use crate::loss::Loss;
use crate::network::nprt_net::NprtNet;
use crate::precision::Precision;
use nprt_gpu::{groups_for, Dispatch, GpuDevice};
use nprt_gpu::{KernelTime, KernelTimer};

/// A network's parameters, gradients and Adam moments on the device, and the step that trains
/// them.
pub struct GpuTrainer {
    pub(crate) gpu: Arc<GpuDevice>,
    layout: ParameterLayout,
    /// Where each tensor lies, in the network's structure.
    pub(crate) net: NetworkLayout,
    /// The network's shapes on the host (their values are the initial ones, not kept current).
    shapes: NprtNet,
    pub(crate) params: wgpu::Buffer,
    pub(crate) grads: wgpu::Buffer,
    pub(crate) resolutions: wgpu::Buffer,
    /// The step's dispatches for the last batch shapes used (training's and validation's, and
    /// their epochs' last, shorter batches), recorded again for every batch of the shape;
    /// the most recently used last.
    plans: Plans<StepPlan>,
    adam: DeviceAdam,
    precision: Precision,
    /// In mixed precision, the dispatches that copy the transport layers' weights into their
    /// f16 copies, run after Adam (none in f32).
    half_refresh: Vec<Dispatch>,
    /// Two host-readable copies of a step's loss, used in turn: one step's is read while the
    /// next one runs.
    loss_copies: [wgpu::Buffer; 2],
    /// The last queued step whose loss has not been read.
    pending: Option<PendingLoss>,
    /// The training set, where the device holds it: steps then gather their batches.
    dataset: Option<DeviceDataset>,
}

/// Where a step's batch comes from.
#[derive(Clone, Copy)]
enum Inputs<'a> {
    /// Gathered on the host.
    Host(&'a Samples<'a>),
    /// Picked on the host, gathered from the dataset on the device (see
    /// [`GpuTrainer::queue_picked_step`]).
    Picked {
        records: &'a [u32],
        views: &'a [u32],
        light_width: usize,
    },
}

impl Inputs<'_> {
    /// Rows, views, the maps' width and the transfer vectors' coefficients per channel (0:
    /// radiance targets).
    fn shape(&self) -> (usize, usize, usize, usize) {
        match *self {
            Inputs::Host(b) => (
                b.len(),
                b.lights.len() / (3 * b.light_width * b.light_width / 2),
                b.light_width,
                b.transfer.len() / (3 * b.len().max(1)),
            ),
            Inputs::Picked {
                records,
                views,
                light_width,
            } => (records.len() / 2, views.len(), light_width, 0),
        }
    }
}

/// A queued step's loss on its way back: its copy, its submission and its batch's rows.
struct PendingLoss {
    copy: usize,
    submission: wgpu::SubmissionIndex,
    rows: usize,
}

/// A training step's dispatches for one batch shape and loss, with the buffers its batches are
/// written into. Its bind groups hold every buffer the step uses, so a step allocates nothing.
struct StepPlan {
    loss: Loss,
    batch: BatchBuffers,
    dispatches: Vec<Dispatch>,
    /// How many of the dispatches make the loss (the forward passes); the rest are backward.
    forward: usize,
    /// With a dataset on the device: the batch's gather, one dispatch per shard of records.
    gathers: Vec<Dispatch>,
}

/// A batch on the device, and what its step computes besides gradients.
pub(crate) struct BatchBuffers {
    pub rows: usize,
    /// What the loss's gradient is multiplied by, and Adam divides by: 1 in f32; in mixed
    /// precision 3 · rows rounded up to a power of two, which makes the gradient at the outputs
    /// that of the loss summed over the batch's values, well within f16's range.
    pub grad_scale: f32,
    pub views: usize,
    pub light_width: usize,
    pub lights: wgpu::Buffer,
    pub features: wgpu::Buffer,
    pub radiance: wgpu::Buffer,
    pub scale: wgpu::Buffer,
    /// Each sample's map, u32.
    pub view: wgpu::Buffer,
    pub codes: wgpu::Buffer,
    pub d_codes: wgpu::Buffer,
    /// The tracks' radiance summed (before the map's scale), and the loss's gradient there.
    pub radiance_sum: wgpu::Buffer,
    pub d_radiance: wgpu::Buffer,
    pub row_loss: wgpu::Buffer,
    pub loss: wgpu::Buffer,
    /// A picked batch's records and views (u32; see [`GpuTrainer::queue_picked_step`]).
    pub picks: wgpu::Buffer,
    pub batch_views: wgpu::Buffer,
    /// A batch whose targets are transfer vectors.
    pub transfer: Option<TransferBuffers>,
}

/// A batch's transfer vectors (`rows × 3K` each): the recorded ones, the tracks' sum and the
/// loss's gradient there.
pub(crate) struct TransferBuffers {
    pub coefficients: usize,
    pub target: wgpu::Buffer,
    pub sum: wgpu::Buffer,
    pub d_transfer: wgpu::Buffer,
}

impl GpuTrainer {
    /// Uploads `net`'s parameters to the process's GPU device, with zero Adam moments, to
    /// train in `precision` (f16 needs f16 in the adapter's shaders).
    pub fn new(net: &NprtNet, precision: Precision) -> Result<Self> {
        let gpu = GpuDevice::get()?;
        let half = precision == Precision::F16;
        if half {
            gpu.check_half()?;
        }
        let shapes = net.clone();
        let (layout, flat) = ParameterLayout::pack_for(&gpu, net);
        let net = NetworkLayout::new(&gpu, &layout, net, half);
        let params = gpu.upload(&flat);
        let grads = gpu.buffer(layout.total);
        let adam = DeviceAdam::new(&gpu, layout.total, &grads, &params);
        let half_refresh = net.half_refresh(&gpu, &params);
        if !half_refresh.is_empty() {
            gpu.submit(&half_refresh);
        }
        let loss_copy = || {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("loss"),
                size: 4,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        Ok(GpuTrainer {
            loss_copies: [loss_copy(), loss_copy()],
            pending: None,
            dataset: None,
            params,
            grads,
            adam,
            precision,
            half_refresh,
            plans: Plans::default(),
            resolutions: gpu.upload(&hash_grid::resolutions()),
            net,
            layout,
            shapes,
            gpu,
        })
    }

    /// The device's adapter, for reports.
    pub fn adapter(&self) -> &str {
        &self.gpu.adapter
    }

    /// The trainer's parameters and gradients, for the MLPs' passes.
    pub(crate) fn trainable(&self) -> Trainable<'_> {
        Trainable {
            gpu: &self.gpu,
            params: &self.params,
            grads: &self.grads,
        }
    }

    /// The parameters' current values, in the network's shapes.
    pub fn parameters(&self) -> NprtNet {
        let flat = self.gpu.read(&self.params, self.layout.total);
        self.layout.unpack(&flat, &self.shapes)
    }

    /// Whether the transport networks' products run in f16 ([`Precision::F16`]).
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// The gradients of the last step, in the network's shapes (its loss scale divided out).
    pub fn gradients(&self) -> NprtNet {
        let scale = self.plans.last().map_or(1.0, |p| p.batch.grad_scale);
        let flat: Vec<f32> = self
            .gpu
            .read(&self.grads, self.layout.total)
            .into_iter()
            .map(|g| g / scale)
            .collect();
        self.layout.unpack(&flat, &self.shapes)
    }

    /// The loss of `batch` and every parameter's gradient, kept on the device
    /// ([`Self::gradients`] reads them): one submission of the encoder's and the transport
    /// networks' forward and backward passes. Reading the loss back waits for it.
    pub fn backward(&mut self, batch: &Samples, loss: Loss) -> f64 {
        self.queue(Inputs::Host(batch), loss, Pass::Backward);
        self.finish().expect("a step was queued")
    }

    /// One training step, waiting for it: [`Self::queue_step`] and [`Self::finish`].
    pub fn step(&mut self, batch: &Samples, loss: Loss, lr: f64) -> f64 {
        self.queue_step(batch, loss, lr);
        self.finish().expect("a step was queued")
    }

    /// Queues one training step: [`Self::backward`] and Adam at learning rate `lr` over every
    /// parameter, in one submission. Returns the loss of the step queued before it (None for
    /// the first), read back while this one runs: the host waits for a step only once the
    /// device has the next, so the device does not idle while the host writes a batch.
    pub fn queue_step(&mut self, batch: &Samples, loss: Loss, lr: f64) -> Option<f64> {
        self.queue(Inputs::Host(batch), loss, Pass::Step(lr))
    }

    /// The device the steps run on.
    pub fn gpu(&self) -> &GpuDevice {
        &self.gpu
    }

    /// Holds `dataset` on the device from now on, for [`Self::queue_picked_step`].
    pub fn hold(&mut self, dataset: DeviceDataset) {
        self.dataset = Some(dataset);
        self.plans.clear();
    }

    /// [`Self::queue_step`] on a batch gathered on the device from the dataset it holds
    /// ([`Self::hold`]): `records` holds each sample's record index in the pack and its view
    /// within the batch, `views` each of the batch's views' index among the training views.
    pub fn queue_picked_step(
        &mut self,
        records: &[u32],
        views: &[u32],
        light_width: usize,
        loss: Loss,
        lr: f64,
    ) -> Option<f64> {
        assert!(self.dataset.is_some(), "no dataset is held on the device");
        let inputs = Inputs::Picked {
            records,
            views,
            light_width,
        };
        self.queue(inputs, loss, Pass::Step(lr))
    }

    /// The loss of the last queued step, once it is done (None if every loss was read).
    pub fn finish(&mut self) -> Option<f64> {
        let pending = self.pending.take()?;
        let copy = &self.loss_copies[pending.copy];
        let total: f32 = self.gpu.read_mapped(copy, pending.submission)[0];
        Some(total as f64 / (3 * pending.rows.max(1)) as f64)
    }

    /// The mean `loss` of `batch` under the current parameters, waiting for it: the forward
    /// passes alone (validation).
    pub fn loss(&mut self, batch: &Samples, loss: Loss) -> f64 {
        self.queue(Inputs::Host(batch), loss, Pass::Forward);
        self.finish().expect("a pass was queued")
    }

    /// One training step on `batch` like [`Self::step`], each dispatch timed on the device:
    /// the GPU time of each kernel, longest first (`nprt bench train --profile`). It waits for
    /// a step still queued first and drops that step's loss and its own, so it is for
    /// benchmarks, not for a training loop. An error where the adapter has no timestamp queries.
    pub fn profile_step(
        &mut self,
        batch: &Samples,
        loss: Loss,
        lr: f64,
    ) -> Result<Vec<KernelTime>> {
        self.finish();
        let inputs = Inputs::Host(batch);
        let pass = Pass::Step(lr);
        self.prepare(inputs, loss);
        let mut timer = KernelTimer::new(&self.gpu, self.dispatches(inputs, pass).len())?;
        // Its loss is left unread: reading the timestamps waits for the submission.
        let (submission, _, _) = self.submit(inputs, pass, Some(&mut timer));
        Ok(timer.read(&self.gpu, submission))
    }

    fn queue(&mut self, inputs: Inputs, loss: Loss, pass: Pass) -> Option<f64> {
        self.prepare(inputs, loss);
        let (submission, copy, rows) = self.submit(inputs, pass, None);
        let before = self.finish();
        self.pending = Some(PendingLoss {
            copy,
            submission,
            rows,
        });
        before
    }

    /// What a submission of the last prepared plan runs, in order: the batch's gather (from a
    /// dataset on the device), the plan's forward part or all of it, and Adam for a step.
    fn dispatches(&self, inputs: Inputs, pass: Pass) -> Vec<&Dispatch> {
        let plan = self.plans.last().expect("prepared");
        let mut list: Vec<&Dispatch> = Vec::new();
        if matches!(inputs, Inputs::Picked { .. }) {
            list.extend(&plan.gathers);
        }
        list.extend(pass.of(&plan.dispatches, plan.forward));
        if let Pass::Step(_) = pass {
            list.push(&self.adam.dispatch);
            list.extend(&self.half_refresh);
        }
        list
    }

    /// Submits the last prepared plan (in one compute pass, or each dispatch timed by
    /// `timer`) with a copy of its loss into the loss copy not awaiting a read; returns the
    /// submission, that copy and the batch's rows.
    fn submit(
        &mut self,
        inputs: Inputs,
        pass: Pass,
        timer: Option<&mut KernelTimer>,
    ) -> (wgpu::SubmissionIndex, usize, usize) {
        if let Pass::Step(lr) = pass {
            let scale = self.plans.last().expect("prepared").batch.grad_scale;
            self.adam.next_step(&self.gpu, self.layout.total, lr, scale);
        }
        let plan = self.plans.last().expect("prepared");
        let copy = self.pending.as_ref().map_or(0, |p| 1 - p.copy);
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        // Every gradient is written whole each step; only the codes' is added to, per track.
        encoder.clear_buffer(&plan.batch.d_codes, 0, None);
        if let (Inputs::Picked { views, .. }, Some(dataset)) = (inputs, &self.dataset) {
            let size = (dataset.light_floats * 4) as u64;
            for (k, &v) in views.iter().enumerate() {
                let (from, to) = (v as u64 * size, k as u64 * size);
                encoder.copy_buffer_to_buffer(&dataset.lights, from, &plan.batch.lights, to, size);
            }
        }
        let dispatches = self.dispatches(inputs, pass);
        match timer {
            Some(timer) => timer.record(&mut encoder, &dispatches),
            None => {
                let mut compute = encoder.begin_compute_pass(&Default::default());
                dispatches.iter().for_each(|d| d.record(&mut compute));
            }
        }
        encoder.copy_buffer_to_buffer(&plan.batch.loss, 0, &self.loss_copies[copy], 0, 4);
        let submission = self.gpu.queue.submit([encoder.finish()]);
        (submission, copy, plan.batch.rows)
    }

    /// Makes the plan for `inputs`' shape and `loss` the last of the kept plans (made unless
    /// one fits), and writes the batch (or its picks) into its buffers.
    fn prepare(&mut self, inputs: Inputs, loss: Loss) {
        let shape = inputs.shape();
        let fits = self.plans.take(|p| {
            let b = &p.batch;
            let transfer = b.transfer.as_ref().map_or(0, |t| t.coefficients);
            p.loss == loss && (b.rows, b.views, b.light_width, transfer) == shape
        });
        let plan = match fits {
            Some(plan) => plan,
            None => {
                let b = self.batch_buffers(shape);
                let mut dispatches = Vec::new();
                let (gpu, params) = (&self.gpu, &self.params);
                // The light model's forward pass, then the transport's, then the light
                // model's backward.
                let tape = match &self.net.light {
                    LightAt::Encoder(e) => {
                        let maps = [b.views, b.light_width];
                        let lights = &b.lights;
                        Some(e.record(gpu, &mut dispatches, params, lights, maps, &b.codes, true))
                    }
                    LightAt::Basis(basis) => {
                        dispatches
                            .push(basis.record_project(gpu, params, &b.lights, b.views, &b.codes));
                        None
                    }
                };
                let forward = self.record_transport(&mut dispatches, &b, loss);
                match (&self.net.light, &tape) {
                    (LightAt::Encoder(e), Some(tape)) => {
                        let buffers = [params, &self.grads];
                        e.record_backward(gpu, &mut dispatches, buffers, b.views, &b.d_codes, tape);
                    }
                    (LightAt::Basis(basis), _) => dispatches.extend(basis.record_backward(
                        gpu,
                        &self.grads,
                        &b.lights,
                        b.views,
                        &b.d_codes,
                    )),
                    (LightAt::Encoder(_), None) => unreachable!("an encoder keeps its tape"),
                }
                StepPlan {
                    loss,
                    gathers: self.gathers(&b),
                    batch: b,
                    dispatches,
                    forward,
                }
            }
        };
        self.plans.keep(plan);
        let b = &self.plans.last().expect("made above").batch;
        match inputs {
            Inputs::Host(batch) => {
                let view: Vec<u32> = batch.view.iter().map(|&v| v as u32).collect();
                self.gpu.write(&b.lights, batch.lights);
                self.gpu.write(&b.features, batch.features);
                self.gpu.write(&b.radiance, batch.radiance);
                self.gpu.write(&b.scale, batch.scale);
                self.gpu.write(&b.view, &view);
                if let Some(t) = &b.transfer {
                    self.gpu.write(&t.target, batch.transfer);
                }
            }
            Inputs::Picked { records, views, .. } => {
                self.gpu.write(&b.picks, records);
                self.gpu.write(&b.batch_views, views);
            }
        }
    }

    /// The dispatches that gather a picked batch into `b` from the dataset the device holds
    /// (none without one).
    fn gathers(&self, b: &BatchBuffers) -> Vec<Dispatch> {
        let Some(dataset) = &self.dataset else {
            return Vec::new();
        };
        dataset
            .shards
            .iter()
            .map(|shard| {
                let mut params = vec![b.rows as u32, shard.first, shard.count, 0];
                params.extend(dataset.bounds.map(f32::to_bits));
                self.gpu.prepare(
                    &GATHER_SAMPLES,
                    &params,
                    &[
                        &shard.records,
                        &b.picks,
                        &b.batch_views,
                        &dataset.scales,
                        &b.features,
                        &b.radiance,
                        &b.scale,
                        &b.view,
                    ],
                    groups_for(b.rows),
                )
            })
            .collect()
    }

    /// Writes Adam's state to `path` as the host's Adam does, so that either engine resumes it.
    pub fn save_state(&self, path: &Path) -> Result<()> {
        self.adam.save(&self.gpu, &self.layout, path)
    }

    /// Reads Adam's state back from `path`, written by either engine for a network of the same
    /// shapes.
    pub fn load_state(&mut self, path: &Path) -> Result<()> {
        self.adam.load(&self.gpu, &self.layout, path)
    }

    /// Buffers for batches of `rows` samples over `views` maps `light_width` wide, with
    /// transfer vectors of `transfer` coefficients per channel (0: none).
    fn batch_buffers(
        &self,
        (rows, views, light_width, transfer): (usize, usize, usize, usize),
    ) -> BatchBuffers {
        let gpu = &self.gpu;
        let grad_scale = match self.precision() {
            Precision::F32 => 1.0,
            Precision::F16 => (3 * rows).next_power_of_two() as f32,
        };
        BatchBuffers {
            rows,
            grad_scale,
            views,
            light_width,
            lights: gpu.buffer(views * 3 * light_width * light_width / 2),
            features: gpu.buffer(rows * FEATURES),
            radiance: gpu.buffer(rows * 3),
            scale: gpu.buffer(rows * 3),
            view: gpu.buffer(rows),
            codes: gpu.buffer(views * self.net.light.code_size()),
            d_codes: gpu.buffer(views * self.net.light.code_size()),
            radiance_sum: gpu.buffer(rows * 3),
            d_radiance: gpu.buffer(rows * 3),
            row_loss: gpu.buffer(rows),
            loss: gpu.buffer(1),
            picks: gpu.buffer(2 * rows),
            batch_views: gpu.buffer(views),
            transfer: (transfer > 0).then(|| TransferBuffers {
                coefficients: transfer,
                target: gpu.buffer(rows * 3 * transfer),
                sum: gpu.buffer(rows * 3 * transfer),
                d_transfer: gpu.buffer(rows * 3 * transfer),
            }),
        }
    }
}
