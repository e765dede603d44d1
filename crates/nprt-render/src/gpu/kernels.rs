//! The frame path's compute kernels: their WGSL sources, compiled pipelines and the one way a
//! dispatch is recorded (a uniform block of parameters at binding 0, storage buffers after it).

use wgpu::util::DeviceExt;

/// A kernel's name and WGSL source: what the device compiles and `nprt export` writes.
pub struct KernelSource {
    pub name: &'static str,
    pub wgsl: &'static str,
}

/// Every kernel of the frame path, in the order a frame first uses them.
pub const SOURCES: [KernelSource; 5] = [
    KernelSource {
        name: "encoder_block",
        wgsl: include_str!("shaders/encoder_block.wgsl"),
    },
    KernelSource {
        name: "track_inputs",
        wgsl: include_str!("shaders/track_inputs.wgsl"),
    },
    KernelSource {
        name: "dense",
        wgsl: include_str!("shaders/dense.wgsl"),
    },
    KernelSource {
        name: "code_bias",
        wgsl: include_str!("shaders/code_bias.wgsl"),
    },
    KernelSource {
        name: "combine",
        wgsl: include_str!("shaders/combine.wgsl"),
    },
];

/// Which kernel a dispatch runs (an index into [`SOURCES`]).
#[derive(Clone, Copy)]
pub enum Kernel {
    EncoderBlock,
    TrackInputs,
    Dense,
    CodeBias,
    Combine,
}

/// Threads per workgroup of the one-dimensional kernels (all but `dense`).
pub const GROUP: u32 = 64;
/// Rows and columns of the tile a `dense` workgroup computes.
pub const DENSE_TILE: u32 = 64;

/// The compiled pipelines, one per kernel.
pub struct Kernels {
    pipelines: Vec<wgpu::ComputePipeline>,
}

impl Kernels {
    pub fn new(device: &wgpu::Device) -> Self {
        let pipelines = SOURCES
            .iter()
            .map(|k| {
                let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(k.name),
                    source: wgpu::ShaderSource::Wgsl(k.wgsl.into()),
                });
                device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(k.name),
                    layout: None,
                    module: &module,
                    entry_point: Some("main"),
                    compilation_options: Default::default(),
                    cache: None,
                })
            })
            .collect();
        Kernels { pipelines }
    }

    /// Records one dispatch of `kernel` with `params` (the shader's uniform struct, as u32
    /// words or f32 bit patterns) and `buffers` at bindings 1, 2, ….
    pub fn dispatch(
        &self,
        device: &wgpu::Device,
        pass: &mut wgpu::ComputePass,
        kernel: Kernel,
        params: &[u32],
        buffers: &[&wgpu::Buffer],
        groups: [u32; 2],
    ) {
        let pipeline = &self.pipelines[kernel as usize];
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(SOURCES[kernel as usize].name),
            contents: bytemuck::cast_slice(params),
            usage: wgpu::BufferUsages::UNIFORM,
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
                    resource: b.as_entire_binding(),
                }),
        );
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(SOURCES[kernel as usize].name),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &entries,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(groups[0], groups[1], 1);
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
