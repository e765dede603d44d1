//! The G-buffer rasterised on the GPU: a visibility pass (each pixel centre's nearest triangle,
//! by the hardware rasteriser) and a compute pass that shades the kept triangle as the tracer
//! would, so that the frame path's G-buffer matches `crate::render_gbuffer`'s (its
//! pixel-centre rays) without tracing a ray. The scene it uploads also serves the path tracer
//! on the device (`path_tracer.rs`).

use std::sync::{Arc, Mutex};

use anyhow::Result;
use glam::{DMat4, DVec4};
use nprt_gpu::{Bind, BufferPool, GpuDevice, KernelSource, PooledBuffer};
use nprt_scene::Camera;
use wgpu::util::DeviceExt;

use super::gpu_map::GpuMap;
use super::gpu_scene::GpuScene;
use crate::{GBuffer, GSample, TraceScene};

/// The compute pass that turns kept triangles into G-buffer samples.
pub const GBUFFER: KernelSource = KernelSource {
    name: "gbuffer",
    wgsl: concat!(
        include_str!("shaders/camera_ray.wgsl"),
        include_str!("shaders/lerp.wgsl"),
        include_str!("shaders/surface.wgsl"),
        include_str!("shaders/gbuffer.wgsl")
    ),
};

/// Floats per pixel of the resolved G-buffer: GSample's fields in order.
pub const SAMPLE_FLOATS: usize = 17;

/// The near plane, as a fraction of the scene's extent: the tracer sees everything in front
/// of the camera, and a reversed f32 depth keeps its precision however near the plane is.
const NEAR: f64 = 1e-6;

/// A scene uploaded once, rasterised into G-buffers of any camera.
pub struct RasterGBuffer {
    gpu: Arc<GpuDevice>,
    scene: GpuScene,
    /// The last map [`Self::trace`] lit the scene by.
    maps: GpuMap,
    visibility: wgpu::RenderPipeline,
    /// The last frame size's targets, reused while the size holds.
    targets: Mutex<Option<Targets>>,
    /// G-buffers and traced frames dropped, for the next of the same size.
    pool: BufferPool,
}

/// What one frame size needs: the kept triangle per pixel and its depth.
struct Targets {
    size: (u32, u32),
    visible: wgpu::Texture,
    depth: wgpu::TextureView,
}

/// A texture bound to a compute kernel (nprt-net's dispatch binds buffers and these).
struct TextureBinding(wgpu::TextureView);

impl Bind for TextureBinding {
    fn resource(&self) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::TextureView(&self.0)
    }
}

impl RasterGBuffer {
    /// Uploads `ts`'s scene to the process's GPU device.
    pub fn new(ts: &TraceScene) -> Result<Self> {
        let gpu = GpuDevice::get()?;
        let module = gpu
            .device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("visibility"),
                source: wgpu::ShaderSource::Wgsl(include_str!("shaders/visibility.wgsl").into()),
            });
        let visibility = gpu
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("visibility"),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vertex"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                // Both faces: the tracer's rays hit triangles from either side.
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Greater),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fragment"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::TextureFormat::R32Uint.into())],
                }),
                multiview_mask: None,
                cache: None,
            });
        Ok(RasterGBuffer {
            scene: GpuScene::new(&gpu, ts)?,
            maps: GpuMap::default(),
            gpu,
            visibility,
            targets: Mutex::new(None),
            pool: BufferPool::default(),
        })
    }

    pub fn device(&self) -> &GpuDevice {
        &self.gpu
    }

    pub fn scene(&self) -> &GpuScene {
        &self.scene
    }

    /// Whether the scene's BVH was built yet: it is, by the first path traced on the device.
    pub fn has_bvh(&self) -> bool {
        self.scene.has_bvh()
    }

    /// A buffer of `floats` f32 a dropped G-buffer or traced frame of that size handed back,
    /// or a new one.
    pub fn pooled(&self, floats: usize) -> PooledBuffer {
        self.pool.take_pooled(&self.gpu, floats)
    }

    pub fn maps(&self) -> &GpuMap {
        &self.maps
    }

    /// The G-buffer of `camera`'s pixel centres, read back.
    pub fn render(&self, camera: &Camera) -> Result<GBuffer> {
        let samples = self.samples(camera)?;
        let pixels = (camera.width * camera.height) as usize;
        let values = self.gpu.read(&samples, pixels * SAMPLE_FLOATS);
        let mut g = GBuffer::default();
        for s in values.chunks_exact(SAMPLE_FLOATS) {
            let v = |k: usize| glam::Vec3::from_slice(&s[k..k + 3]);
            g.push(GSample {
                position: v(0),
                normal: v(3),
                view: v(6),
                kd: v(9),
                ks: v(12),
                alpha: s[15],
                mask: s[16],
            });
        }
        Ok(g)
    }

    /// The G-buffer of `camera`'s pixel centres on the device: GSample's fields, 17 f32 per
    /// pixel in row order, in a buffer of its own (queued; later submissions may read it).
    pub fn samples(&self, camera: &Camera) -> Result<PooledBuffer> {
        let gpu = &*self.gpu;
        let what = format!("the G-buffer of a {}×{} frame", camera.width, camera.height);
        gpu.check_frame(camera.width, camera.height, &what)?;
        let pixels = (camera.width * camera.height) as usize;
        gpu.check_binding(4 * SAMPLE_FLOATS * pixels, &what)?;
        let size = (camera.width, camera.height);
        let mut kept = self.targets.lock().unwrap_or_else(|e| e.into_inner());
        let targets = match kept.take() {
            Some(t) if t.size == size => t,
            _ => self.targets(size),
        };
        let visible = TextureBinding(targets.visible.create_view(&Default::default()));
        let samples = self.pooled(pixels * SAMPLE_FLOATS);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.record_visibility(&mut encoder, camera, &targets.depth, &visible);
        let scene = &self.scene;
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            let mut params = vec![camera.width, camera.height, 0, 0];
            params.extend(camera_words(camera));
            gpu.dispatch(
                &mut pass,
                &GBUFFER,
                &params,
                &[
                    &visible,
                    &scene.positions,
                    &scene.attributes,
                    &scene.triangles,
                    &scene.materials,
                    &scene.textures,
                    &scene.bitmaps,
                    &samples,
                ],
                [camera.width.div_ceil(8), camera.height.div_ceil(8)],
            );
        }
        gpu.queue.submit([encoder.finish()]);
        *kept = Some(targets);
        Ok(samples)
    }

    /// Records the visibility pass of `camera` into `visible` (each pixel's nearest
    /// triangle), with the depth buffer `depth`.
    fn record_visibility(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        camera: &Camera,
        depth: &wgpu::TextureView,
        visible: &TextureBinding,
    ) {
        let gpu = &*self.gpu;
        let clip = self.clip(camera);
        let view = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("view"),
                contents: bytemuck::cast_slice(&clip.to_cols_array()),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("visibility"),
            layout: &self.visibility.get_bind_group_layout(0),
            entries: &[
                view.as_entire_binding(),
                self.scene.positions.as_entire_binding(),
                self.scene.triangles.as_entire_binding(),
            ]
            .into_iter()
            .enumerate()
            .map(|(i, resource)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource,
            })
            .collect::<Vec<_>>(),
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("visibility"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &visible.0,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.visibility);
        pass.set_bind_group(0, &group, &[]);
        pass.draw(0..3 * self.scene.triangle_count, 0..1);
    }

    /// World to clip for `camera`: a point's pixel is where `camera.ray` through it would
    /// start (x, y), its depth near / z reversed (1 at the near plane, 0 at infinity). Made in
    /// f64, so that the inverse adds no error of its own.
    fn clip(&self, camera: &Camera) -> glam::Mat4 {
        let tx = camera.tan_half_x() as f64;
        let ty = tx * camera.height as f64 / camera.width as f64;
        let near = NEAR * (self.scene.extent as f64).max(f64::MIN_POSITIVE);
        // Camera::ray's local direction is ((0.5 − sx)·2tx, (0.5 − sy)·2ty, 1): x grows to the
        // left of the film, y upwards, as clip space's y does.
        let project = DMat4::from_cols(
            DVec4::new(-1.0 / tx, 0.0, 0.0, 0.0),
            DVec4::new(0.0, 1.0 / ty, 0.0, 0.0),
            DVec4::new(0.0, 0.0, 0.0, 1.0),
            DVec4::new(0.0, 0.0, near, 0.0),
        );
        (project * camera.to_world.as_dmat4().inverse()).as_mat4()
    }

    fn targets(&self, (width, height): (u32, u32)) -> Targets {
        let texture = |format, usage| {
            self.gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        Targets {
            size: (width, height),
            visible: texture(
                wgpu::TextureFormat::R32Uint,
                attachment | wgpu::TextureUsages::TEXTURE_BINDING,
            ),
            depth: texture(wgpu::TextureFormat::Depth32Float, attachment)
                .create_view(&Default::default()),
        }
    }
}

/// `camera` as `camera_ray.wgsl`'s kernels take it: its to_world's columns (x, y, z axes and
/// the origin) and the tangents of its half field of view, five vec4s of f32 bits.
pub fn camera_words(camera: &Camera) -> Vec<u32> {
    let frame = camera.to_world;
    let tx = camera.tan_half_x();
    let ty = tx * camera.height as f32 / camera.width as f32;
    [
        frame.x_axis,
        frame.y_axis,
        frame.z_axis,
        frame.w_axis,
        glam::Vec4::new(tx, ty, 0.0, 0.0),
    ]
    .iter()
    .flat_map(|v| v.to_array().map(f32::to_bits))
    .collect()
}
