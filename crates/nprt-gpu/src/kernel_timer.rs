//! GPU time per kernel of a recorded step, from timestamps written around each dispatch: what
//! `nprt bench train --profile` prints, to show where a step's time goes on a GPU. Each
//! dispatch gets its own compute pass, so the sum is the kernels' time without the overlap a
//! single pass may allow; the step's wall time beside it shows what the host and the launches
//! add.

use anyhow::{bail, Result};

use crate::{Dispatch, GpuDevice};

/// One kernel's share of a step: how often it ran and its GPU time in all.
#[derive(Clone, Debug, PartialEq)]
pub struct KernelTime {
    pub kernel: &'static str,
    pub dispatches: usize,
    pub ms: f64,
}

/// Timestamp queries for `dispatches` dispatches, and the buffers they are read back through.
pub struct KernelTimer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: wgpu::Buffer,
    count: u32,
    /// The kernel of each timed dispatch, in order.
    kernels: Vec<&'static str>,
}

impl KernelTimer {
    /// Two timestamps for each of `dispatches` dispatches; an error where the adapter has no
    /// timestamp queries or the step has more dispatches than one query set holds.
    pub fn new(gpu: &GpuDevice, dispatches: usize) -> Result<Self> {
        if !gpu
            .device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
        {
            bail!("the adapter {} has no timestamp queries", gpu.adapter);
        }
        let count = 2 * dispatches;
        if count > wgpu::QUERY_SET_MAX_QUERIES as usize {
            bail!("a step of {dispatches} dispatches is more than one query set times");
        }
        let count = count as u32;
        let size = 8 * count as u64;
        let buffer = |usage| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("kernel timestamps"),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        Ok(KernelTimer {
            queries: gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("kernel timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolved: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            readback: buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
            count,
            kernels: Vec::new(),
        })
    }

    /// Records each of `dispatches` in a compute pass of its own between two timestamps, then
    /// the copy that brings them back.
    pub fn record(&mut self, encoder: &mut wgpu::CommandEncoder, dispatches: &[&Dispatch]) {
        assert!(
            2 * dispatches.len() <= self.count as usize,
            "more dispatches than timestamps"
        );
        self.kernels = dispatches.iter().map(|d| d.kernel).collect();
        for (i, d) in dispatches.iter().enumerate() {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(d.kernel),
                timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
                    query_set: &self.queries,
                    beginning_of_pass_write_index: Some(2 * i as u32),
                    end_of_pass_write_index: Some(2 * i as u32 + 1),
                }),
            });
            d.record(&mut pass);
        }
        encoder.resolve_query_set(&self.queries, 0..self.count, &self.resolved, 0);
        encoder.copy_buffer_to_buffer(&self.resolved, 0, &self.readback, 0, 8 * self.count as u64);
    }

    /// Once `submission` (holding [`Self::record`]) is done: the time of each kernel, summed
    /// over its dispatches, longest first.
    pub fn read(&self, gpu: &GpuDevice, submission: wgpu::SubmissionIndex) -> Vec<KernelTime> {
        let ticks: Vec<u64> = gpu.read_mapped(&self.readback, submission);
        let ms_per_tick = gpu.queue.get_timestamp_period() as f64 * 1e-6;
        let mut times: Vec<KernelTime> = Vec::new();
        for (&kernel, t) in self.kernels.iter().zip(ticks.chunks_exact(2)) {
            let ms = t[1].saturating_sub(t[0]) as f64 * ms_per_tick;
            match times.iter_mut().find(|k| k.kernel == kernel) {
                Some(k) => {
                    k.dispatches += 1;
                    k.ms += ms;
                }
                None => times.push(KernelTime {
                    kernel,
                    dispatches: 1,
                    ms,
                }),
            }
        }
        times.sort_by(|a, b| b.ms.total_cmp(&a.ms));
        times
    }
}

impl GpuDevice {
    /// The GPU time of each kernel of `dispatches`, run once in order, each in a pass of its
    /// own (`nprt bench frame --profile`). An error where the adapter has no timestamp queries.
    pub fn profile(&self, dispatches: &[&Dispatch]) -> Result<Vec<KernelTime>> {
        let mut timer = KernelTimer::new(self, dispatches.len())?;
        let mut encoder = self.device.create_command_encoder(&Default::default());
        timer.record(&mut encoder, dispatches);
        let submission = self.queue.submit([encoder.finish()]);
        Ok(timer.read(self, submission))
    }
}
