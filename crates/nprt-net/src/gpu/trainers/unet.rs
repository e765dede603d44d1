//! The Deep Shading U-Net trained on the GPU kernels: its parameters, gradients and Adam's
//! moments on the device, a pass recorded once per batch shape (`unet_pass`), and the same
//! calls the CPU engine answers (`DeepShading::loss_and_gradients`, `shade`), so that the
//! training loop and the tests take either.

use std::path::Path;
use std::sync::Arc;

use anyhow::Result;

use crate::cpu::UnetBatch;
use crate::gpu::layers::conv::Images;
use crate::gpu::layers::parameters::ParameterLayout;
use crate::gpu::passes::device_adam::DeviceAdam;
use crate::gpu::passes::unet::{loss_params, UnetAt, UnetBuffers};
use crate::gpu::trainers::plans::{submit, Pass, Plans};
use crate::loss::Loss;
use crate::network::encoder::LightInput;
use crate::network::unet::DeepShading;
use crate::shading::UnetShading;
use nprt_gpu::{Dispatch, GpuDevice};

/// A U-Net's parameters, gradients and Adam moments on the device, and the passes that train
/// and run it.
pub struct GpuUnet {
    gpu: Arc<GpuDevice>,
    layout: ParameterLayout,
    net: UnetAt,
    /// The network's shapes on the host (their values are the initial ones, not kept current).
    shapes: DeepShading,
    params: wgpu::Buffer,
    grads: wgpu::Buffer,
    adam: DeviceAdam,
    /// The passes for the last batch shapes used (training's, validation's, their epochs'
    /// shorter last batches), the most recently used last.
    plans: Plans<UnetPlan>,
}

/// A pass's dispatches for one batch shape and loss, with the buffers its batches are written
/// into.
struct UnetPlan {
    loss: Loss,
    batch: UnetBuffers,
    dispatches: Vec<Dispatch>,
    /// How many of the dispatches make the loss and the prediction; the rest are backward.
    forward: usize,
    /// The loss's dispatch, whose parameters change with the batch's foreground.
    loss_at: usize,
}

impl GpuUnet {
    /// Uploads `net`'s parameters to the process's GPU device, with zero Adam moments.
    pub fn new(net: &DeepShading) -> Result<Self> {
        let gpu = GpuDevice::get()?;
        let (layout, flat) = ParameterLayout::pack_for(&gpu, net);
        let params = gpu.upload(&flat);
        let grads = gpu.buffer(layout.total);
        Ok(GpuUnet {
            adam: DeviceAdam::new(&gpu, layout.total, &grads, &params),
            net: UnetAt::new(net, &layout),
            shapes: net.clone(),
            plans: Plans::default(),
            params,
            grads,
            layout,
            gpu,
        })
    }

    /// The device's adapter, for reports.
    pub fn adapter(&self) -> &str {
        &self.gpu.adapter
    }

    /// The parameters' current values.
    pub fn parameters(&self) -> DeepShading {
        let flat = self.gpu.read(&self.params, self.layout.total);
        self.layout.unpack(&flat, &self.shapes)
    }

    /// The gradients of the last backward pass or step.
    pub fn gradients(&self) -> DeepShading {
        let flat = self.gpu.read(&self.grads, self.layout.total);
        self.layout.unpack(&flat, &self.shapes)
    }

    /// The batch's mean masked `loss` (over every foreground pixel's channels), as
    /// `DeepShading::loss_and_gradients` makes it, and every gradient, kept on the device
    /// ([`Self::gradients`] reads them).
    pub fn backward(&mut self, batch: &UnetBatch, loss: Loss) -> f64 {
        self.run(batch, loss, Pass::Backward)
    }

    /// One training step: [`Self::backward`], then Adam at learning rate `lr`.
    pub fn step(&mut self, batch: &UnetBatch, loss: Loss, lr: f64) -> f64 {
        self.run(batch, loss, Pass::Step(lr))
    }

    /// The batch's mean masked `loss` under the current parameters (validation).
    pub fn loss(&mut self, batch: &UnetBatch, loss: Loss) -> f64 {
        self.run(batch, loss, Pass::Forward)
    }

    /// The radiance of the batch's views (views × 3 × h × w), as `DeepShading::shade` makes
    /// it; the batch's radiance and mask are not read.
    pub fn shade(&mut self, batch: &UnetBatch) -> Vec<f32> {
        self.run(batch, Loss::LogL1, Pass::Forward);
        let b = &self.plans.last().expect("run").batch;
        self.gpu.read(&b.prediction, b.images.values(3))
    }

    /// Writes Adam's state to `path` as the host's Adam does, so that either engine resumes it.
    pub fn save_state(&self, path: &Path) -> Result<()> {
        self.adam.save(&self.gpu, &self.layout, path)
    }

    /// Reads Adam's state back from `path`, written by either engine.
    pub fn load_state(&mut self, path: &Path) -> Result<()> {
        self.adam.load(&self.gpu, &self.layout, path)
    }

    fn run(&mut self, batch: &UnetBatch, loss: Loss, pass: Pass) -> f64 {
        let images = Images {
            views: batch.scale.len() / 3,
            h: batch.height,
            w: batch.width,
        };
        self.prepare(images, batch.light_width, loss);
        let gpu = &self.gpu;
        let plan = self.plans.last().expect("prepared");
        let b = &plan.batch;
        gpu.write(&b.features, &batch.features);
        gpu.write(&b.radiance, &batch.radiance);
        gpu.write(&b.mask, &batch.mask);
        gpu.write(&b.lights, &batch.lights);
        gpu.write(&b.scale, &batch.scale);
        let foreground: f64 = batch.mask.iter().map(|&m| m as f64).sum();
        let uniform = &plan.dispatches[plan.loss_at].uniform;
        gpu.write(uniform, &loss_params(images, loss, foreground));
        let recorded = (plan.dispatches.as_slice(), plan.forward);
        submit(gpu, recorded, pass, (&mut self.adam, self.layout.total));
        let total = gpu.read(&b.loss, 1)[0] as f64;
        total / (3.0 * foreground).max(1.0)
    }

    /// Makes the plan for `images` and `loss` the last of the kept plans (made unless one
    /// fits).
    fn prepare(&mut self, images: Images, light_width: usize, loss: Loss) {
        let fits = self.plans.take(|p| {
            let b = &p.batch;
            let shape = (b.images.views, b.images.h, b.images.w, b.light_width);
            p.loss == loss && shape == (images.views, images.h, images.w, light_width)
        });
        let plan = match fits {
            Some(plan) => plan,
            None => {
                let gpu = &self.gpu;
                let batch = UnetBuffers::new(gpu, images, light_width, self.net.offset_width());
                let mut dispatches = Vec::new();
                let (tape, loss_at) =
                    self.net
                        .record_forward(gpu, &mut dispatches, &self.params, &batch, loss);
                let forward = dispatches.len();
                let buffers = [&self.params, &self.grads];
                self.net
                    .record_backward(gpu, &mut dispatches, buffers, &batch, &tape);
                UnetPlan {
                    loss,
                    batch,
                    dispatches,
                    forward,
                    loss_at,
                }
            }
        };
        self.plans.keep(plan);
    }
}

/// One view at a time: the U-Net's buffers are the trainer's.
impl UnetShading for std::sync::Mutex<GpuUnet> {
    fn radiance(&self, features: Vec<f32>, light: LightInput, (h, w): (usize, usize)) -> Vec<f32> {
        let batch = UnetBatch {
            features,
            radiance: vec![0.0; 3 * h * w],
            mask: vec![0.0; h * w],
            lights: light.pixels,
            light_width: light.width,
            scale: light.scale.to_vec(),
            height: h,
            width: w,
        };
        self.lock().unwrap_or_else(|e| e.into_inner()).shade(&batch)
    }
}
