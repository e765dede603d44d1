//! A compute kernel: its WGSL source, its pipeline (compiled once per device, at first use) and
//! the one way a dispatch is recorded: a uniform block of parameters at binding 0, storage
//! buffers after it.

use std::collections::HashMap;
use std::sync::Mutex;

use wgpu::util::DeviceExt;

use crate::Span;

/// A kernel's name and WGSL source: what the device compiles and `nprt export` writes.
pub struct KernelSource {
    pub name: &'static str,
    pub wgsl: &'static str,
}

impl KernelSource {
    /// A kernel whose source is `parts` one after another (WGSL has no includes), for parts
    /// that another crate owns; made once (in a `LazyLock`): its source lives as long as the
    /// process.
    pub fn joined(name: &'static str, parts: &[&str]) -> KernelSource {
        KernelSource {
            name,
            wgsl: Box::leak(parts.concat().into_boxed_str()),
        }
    }
}

/// Threads per workgroup of the one-dimensional kernels.
pub const GROUP: u32 = 64;

/// A device's compiled pipelines, by kernel name.
#[derive(Default)]
pub(crate) struct Pipelines {
    compiled: Mutex<HashMap<&'static str, wgpu::ComputePipeline>>,
}

impl Pipelines {
    /// `kernel`'s pipeline, compiled on first use.
    fn get(&self, device: &wgpu::Device, kernel: &KernelSource) -> wgpu::ComputePipeline {
        let mut compiled = self.compiled.lock().unwrap_or_else(|e| e.into_inner());
        compiled
            .entry(kernel.name)
            .or_insert_with(|| {
                let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(kernel.name),
                    source: wgpu::ShaderSource::Wgsl(kernel.wgsl.into()),
                });
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(kernel.name),
                    layout: None,
                    module: &module,
                    entry_point: Some("main"),
                    compilation_options: Default::default(),
                    cache: None,
                })
            })
            .clone()
    }
}

/// One dispatch ready to record: its pipeline, its bind group (which keeps its buffers alive)
/// and its workgroups. A training step keeps its dispatches and records them again each step.
pub struct Dispatch {
    /// The kernel's name, for [`crate::KernelTime`].
    pub kernel: &'static str,
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    groups: [u32; 3],
    /// The parameter block, rewritable with `queue.write_buffer` (Adam's rate and step).
    pub uniform: wgpu::Buffer,
}

impl Dispatch {
    pub fn record(&self, pass: &mut wgpu::ComputePass) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.dispatch_workgroups(self.groups[0], self.groups[1], self.groups[2]);
    }
}

impl crate::GpuDevice {
    /// Submits `dispatches` in one compute pass, in order; the caller reads back what it needs.
    pub fn submit<'a>(&self, dispatches: impl IntoIterator<Item = &'a Dispatch>) {
        let mut encoder = self.device.create_command_encoder(&Default::default());
        let mut pass = encoder.begin_compute_pass(&Default::default());
        dispatches.into_iter().for_each(|d| d.record(&mut pass));
        drop(pass);
        self.queue.submit([encoder.finish()]);
    }

    /// A dispatch of `kernel` with `params` (the shader's uniform struct, as u32 words or f32
    /// bit patterns) and `buffers` (whole buffers or parts) at bindings 1, 2, ….
    pub fn prepare(
        &self,
        kernel: &KernelSource,
        params: &[u32],
        buffers: &[&dyn Bind],
        [x, y]: [u32; 2],
    ) -> Dispatch {
        self.prepare_grid(kernel, params, buffers, [x, y, 1])
    }

    /// [`Self::prepare`] over a three-dimensional grid of workgroups.
    pub fn prepare_grid(
        &self,
        kernel: &KernelSource,
        params: &[u32],
        buffers: &[&dyn Bind],
        groups: [u32; 3],
    ) -> Dispatch {
        let pipeline = self.pipelines.get(&self.device, kernel);
        let uniform = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(kernel.name),
                contents: bytemuck::cast_slice(params),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            });
        let mut entries = vec![wgpu::BindGroupEntry {
            binding: 0,
            resource: uniform.as_entire_binding(),
        }];
        entries.extend(
            buffers
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry {
                    binding: i as u32 + 1,
                    resource: b.resource(),
                }),
        );
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(kernel.name),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        Dispatch {
            kernel: kernel.name,
            pipeline,
            group,
            groups,
            uniform,
        }
    }

    /// Records one dispatch of `kernel` now (see [`Self::prepare`]).
    pub fn dispatch(
        &self,
        pass: &mut wgpu::ComputePass,
        kernel: &KernelSource,
        params: &[u32],
        buffers: &[&dyn Bind],
        groups: [u32; 2],
    ) {
        self.prepare(kernel, params, buffers, groups).record(pass);
    }
}

/// What a kernel binds: a whole storage buffer, or a [`Part`] of one.
pub trait Bind {
    fn resource(&self) -> wgpu::BindingResource<'_>;
}

impl Bind for wgpu::Buffer {
    fn resource(&self) -> wgpu::BindingResource<'_> {
        self.as_entire_binding()
    }
}

/// One tensor of a flat buffer, bound on its own (its offset a multiple of the device's
/// storage-binding alignment).
pub struct Part<'a> {
    pub buffer: &'a wgpu::Buffer,
    pub span: Span,
}

impl Bind for Part<'_> {
    fn resource(&self) -> wgpu::BindingResource<'_> {
        let (offset, size) = self.span.bytes();
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: self.buffer,
            offset,
            size: wgpu::BufferSize::new(size.max(4)),
        })
    }
}

/// Workgroups for `n` threads of a one-dimensional kernel: a second dimension where one would
/// exceed the 65,535 workgroups every adapter allows (the first encoder block of a 1024-wide
/// map has 65,536); the kernels number their threads x + y · (workgroups along x) · 64.
pub fn groups_for(n: usize) -> [u32; 2] {
    let groups = (n as u32).div_ceil(GROUP);
    let rows = groups.div_ceil(MAX_GROUPS);
    [groups.div_ceil(rows), rows]
}

const MAX_GROUPS: u32 = 65_535;
