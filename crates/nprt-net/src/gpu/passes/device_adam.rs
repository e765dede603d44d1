//! Adam on the device: the host's optimiser ([`crate::optimiser::Adam`], burn's formulation)
//! over a network's flat parameter buffer in one dispatch, its moments in two more buffers of
//! the same layout, and its state file the host's, so that either engine resumes it.

use std::path::Path;

use anyhow::Result;

use crate::gpu::kernels::ADAM;
use crate::gpu::layers::parameters::ParameterLayout;
use crate::optimiser::{bias_corrections_for, load_state, save_state, ADAM_BETA1, ADAM_BETA2};
use nprt_gpu::{groups_for, Dispatch, GpuDevice};

/// Adam's moments and step count for one network's flat buffers, and its dispatch.
pub struct DeviceAdam {
    moment1: wgpu::Buffer,
    moment2: wgpu::Buffer,
    /// Steps taken.
    steps: u64,
    /// β1 and β2.
    betas: [f32; 2],
    /// Over every parameter; its rate and bias corrections are rewritten each step.
    pub dispatch: Dispatch,
}

/// The parameter block of `adam.wgsl` for step `t` (from 1) at learning rate `lr`, over
/// `count` values whose gradients are scaled by `grad_scale`.
fn adam_params(count: usize, lr: f64, t: u64, grad_scale: f32, betas: [f32; 2]) -> Vec<u32> {
    let (factor, epsilon) = bias_corrections_for(t, betas);
    let mut params = vec![count as u32, 0, 0, 0];
    params.extend(
        [
            lr as f32,
            betas[0],
            betas[1],
            factor,
            epsilon,
            1.0 / grad_scale,
            0.0,
            0.0,
        ]
        .map(f32::to_bits),
    );
    params
}

impl DeviceAdam {
    /// Zero moments for the `total` values of `params`, stepped by `grads`.
    pub fn new(gpu: &GpuDevice, total: usize, grads: &wgpu::Buffer, params: &wgpu::Buffer) -> Self {
        Self::with_betas(gpu, total, grads, params, [ADAM_BETA1, ADAM_BETA2])
    }

    /// [`Self::new`] with decay rates `[β1, β2]` of one's own (the radiance cache's).
    pub fn with_betas(
        gpu: &GpuDevice,
        total: usize,
        grads: &wgpu::Buffer,
        params: &wgpu::Buffer,
        betas: [f32; 2],
    ) -> Self {
        let zeros = vec![0.0f32; total];
        let [moment1, moment2] = [&zeros, &zeros].map(|v| gpu.upload(v));
        let dispatch = gpu.prepare(
            &ADAM,
            &adam_params(total, 0.0, 1, 1.0, betas),
            &[grads, params, &moment1, &moment2],
            groups_for(total),
        );
        DeviceAdam {
            moment1,
            moment2,
            steps: 0,
            betas,
            dispatch,
        }
    }

    /// Counts a step at learning rate `lr` over `total` values whose gradients arrive times
    /// `grad_scale`, and sets the dispatch for it (recorded after the step's gradients).
    pub fn next_step(&mut self, gpu: &GpuDevice, total: usize, lr: f64, grad_scale: f32) {
        self.steps += 1;
        let params = adam_params(total, lr, self.steps, grad_scale, self.betas);
        gpu.write(&self.dispatch.uniform, &params);
    }

    /// Writes the state to `path` as the host's Adam does (the moments without the layout's
    /// gaps).
    pub fn save(&self, gpu: &GpuDevice, layout: &ParameterLayout, path: &Path) -> Result<()> {
        let total = layout.total;
        let [m1, m2] = [&self.moment1, &self.moment2].map(|m| layout.compact(&gpu.read(m, total)));
        save_state(path, [&m1, &m2], self.steps)
    }

    /// Reads the state back from `path`, written by either engine for a network of the same
    /// shapes.
    pub fn load(&mut self, gpu: &GpuDevice, layout: &ParameterLayout, path: &Path) -> Result<()> {
        // Checkpoints of the kernels from before the shared format hold the moments with the
        // layout's gaps.
        let (moments, steps) = match load_state(path, layout.params()) {
            Ok((m, steps)) => (m.map(|m| layout.expand(&m)), steps),
            Err(e) => load_state(path, layout.total).map_err(|_| e)?,
        };
        for (values, buffer) in moments.iter().zip([&self.moment1, &self.moment2]) {
            gpu.write(buffer, values);
        }
        self.steps = steps;
        Ok(())
    }
}
