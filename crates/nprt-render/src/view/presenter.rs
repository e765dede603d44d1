//! Shows frames in a window through wgpu, on the device the GPU kernels run on: a frame's
//! linear radiance (3 f32 a pixel, left there by the kernels or uploaded from the host) is
//! scaled by the exposure and sRGB-encoded to 8-bit values as `nprt_io::srgb8` does, with the
//! overlay's text laid over it, by one full-screen triangle. A frame the kernels made never
//! visits the host; before, it was read back, encoded on the CPU and uploaded again. A
//! screenshot draws the same into a texture and reads that back.

use std::sync::Arc;

use anyhow::{anyhow, Result};
use nprt_gpu::GpuDevice;
use wgpu::util::DeviceExt;
use winit::window::Window;

use crate::frame_stages::FrameRadiance;

/// Rows of the frame's top the overlay's text may cover.
pub const OVERLAY_ROWS: u32 = 256;

const SHOW: &str = r#"
struct Show {
    width: u32,
    height: u32,
    // Rows of the overlay in use (0: none).
    overlay_rows: u32,
    // 1 where the target encodes sRGB itself on write: it is handed linear values.
    target_srgb: u32,
    // 2^exposure.
    scale: f32,
}

@group(0) @binding(0) var<uniform> p: Show;
@group(0) @binding(1) var<storage, read> rgb: array<f32>;
@group(0) @binding(2) var overlay: texture_2d<f32>;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let q = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(q * 2.0 - 1.0, 0.0, 1.0);
}

fn encode(c: f32) -> f32 {
    let v = clamp(c, 0.0, 1.0);
    if (v <= 0.0031308) {
        return 12.92 * v;
    }
    return 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

fn decode(c: f32) -> f32 {
    if (c <= 0.04045) {
        return c / 12.92;
    }
    return pow((c + 0.055) / 1.055, 2.4);
}

@fragment
fn fs(@builtin(position) at: vec4<f32>) -> @location(0) vec4<f32> {
    let xy = vec2<u32>(at.xy);
    if (xy.x >= p.width || xy.y >= p.height) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let i = 3u * (xy.y * p.width + xy.x);
    let linear = vec3<f32>(rgb[i], rgb[i + 1u], rgb[i + 2u]) * p.scale;
    // The 8-bit values a PNG of the frame holds.
    var c = floor(vec3<f32>(encode(linear.x), encode(linear.y), encode(linear.z)) * 255.0 + 0.5) / 255.0;
    if (xy.y < p.overlay_rows) {
        let o = textureLoad(overlay, vec2<i32>(xy), 0);
        c = mix(c, o.rgb, o.a);
    }
    if (p.target_srgb == 1u) {
        c = vec3<f32>(decode(c.x), decode(c.y), decode(c.z));
    }
    return vec4<f32>(c, 1.0);
}
"#;

/// A window's surface and what draws a frame on it, or into a screenshot.
pub struct Presenter {
    gpu: Arc<GpuDevice>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// The frame's size.
    size: [u32; 2],
    /// Drawing into the window's format, and into an RGBA8 screenshot.
    to_window: wgpu::RenderPipeline,
    to_image: wgpu::RenderPipeline,
    /// The overlay's text, RGBA8 over the frame's top rows, transparent elsewhere.
    overlay: wgpu::Texture,
    /// A host frame's radiance, uploaded.
    host_rgb: wgpu::Buffer,
    /// The adapter's name, for the overlay.
    pub adapter: String,
}

/// What one drawing shows: the frame, its exposure and the overlay (RGBA8, `width ×` at most
/// [`OVERLAY_ROWS`] rows; empty for none).
pub struct Shown<'a> {
    pub frame: &'a FrameRadiance,
    pub exposure: f32,
    pub overlay: &'a [u8],
}

/// `window`'s surface on `gpu`, configured to its size in the first format it offers.
fn window_surface(
    gpu: &GpuDevice,
    window: &Arc<Window>,
) -> Result<(wgpu::Surface<'static>, wgpu::SurfaceConfiguration)> {
    let surface = gpu
        .instance
        .create_surface(window.clone())
        .map_err(|e| anyhow!("cannot draw into the window: {e}"))?;
    let caps = surface.get_capabilities(&gpu.wgpu_adapter);
    let format = *caps.formats.first().ok_or_else(|| {
        anyhow!(
            "the GPU adapter {} cannot draw into this window (its surface offers no format)",
            gpu.adapter
        )
    })?;
    let window_size = window.inner_size();
    let config = wgpu::SurfaceConfiguration {
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        format,
        width: window_size.width.max(1),
        height: window_size.height.max(1),
        present_mode: wgpu::PresentMode::Fifo,
        desired_maximum_frame_latency: 2,
        alpha_mode: caps.alpha_modes[0],
        view_formats: vec![],
        color_space: wgpu::SurfaceColorSpace::Auto,
    };
    surface.configure(&gpu.device, &config);
    Ok((surface, config))
}

impl Presenter {
    /// A presenter for `window` on the GPU kernels' device, whose frames are
    /// `width × height`.
    pub fn new(window: Arc<Window>, width: u32, height: u32) -> Result<Self> {
        let gpu = GpuDevice::get()?;
        let (surface, config) = window_surface(&gpu, &window)?;
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("show"),
            source: wgpu::ShaderSource::Wgsl(SHOW.into()),
        });
        let pipeline = |format: wgpu::TextureFormat| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("show"),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs"),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                multiview_mask: None,
                cache: None,
            })
        };
        let overlay = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("overlay"),
            size: wgpu::Extent3d {
                width,
                height: height.min(OVERLAY_ROWS),
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let info = gpu.wgpu_adapter.get_info();
        Ok(Presenter {
            to_window: pipeline(config.format),
            to_image: pipeline(wgpu::TextureFormat::Rgba8Unorm),
            host_rgb: gpu.buffer(3 * (width * height) as usize),
            adapter: format!("{} ({:?})", info.name, info.backend),
            overlay,
            size: [width, height],
            config,
            surface,
            gpu,
        })
    }

    /// Follows the window's new size.
    pub fn resize(&mut self, width: u32, height: u32) {
        self.config.width = width.max(1);
        self.config.height = height.max(1);
        self.surface.configure(&self.gpu.device, &self.config);
    }

    /// Draws `shown` in the window.
    pub fn present(&mut self, shown: &Shown) -> Result<()> {
        use wgpu::CurrentSurfaceTexture as Current;
        let frame = match self.surface.get_current_texture() {
            Current::Success(frame) | Current::Suboptimal(frame) => frame,
            // A hidden window or a late frame: this one is skipped.
            Current::Timeout | Current::Occluded => return Ok(()),
            Current::Outdated | Current::Lost => {
                self.surface.configure(&self.gpu.device, &self.config);
                return Ok(());
            }
            other => return Err(anyhow!("the window's surface: {other:?}")),
        };
        let srgb = self.config.format.is_srgb();
        let view = frame.texture.create_view(&Default::default());
        let encoder = self.draw(shown, &self.to_window, &view, srgb);
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.queue.present(frame);
        Ok(())
    }

    /// `shown` as the window shows it: RGBA8, the frame's size, rows top first.
    pub fn screenshot(&self, shown: &Shown) -> Vec<u8> {
        let [w, h] = self.size;
        let extent = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        };
        let image = self.gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("screenshot"),
            size: extent,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = image.create_view(&Default::default());
        let mut encoder = self.draw(shown, &self.to_image, &view, false);
        // Rows of a texture copy are 256-byte aligned.
        let row = (4 * w).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let copy = self.gpu.buffer((row * h / 4) as usize);
        encoder.copy_texture_to_buffer(
            image.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &copy,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            extent,
        );
        self.gpu.queue.submit([encoder.finish()]);
        let words = self.gpu.read(&copy, (row * h / 4) as usize);
        let bytes: &[u8] = bytemuck::cast_slice(&words);
        bytes
            .chunks_exact(row as usize)
            .flat_map(|r| &r[..4 * w as usize])
            .copied()
            .collect()
    }

    /// Uploads the overlay's rows (RGBA, the frame's width); returns how many.
    fn upload_overlay(&self, overlay: &[u8]) -> u32 {
        let w = self.size[0];
        let overlay_rows = (overlay.len() / (4 * w as usize)) as u32;
        if overlay_rows > 0 {
            self.gpu.queue.write_texture(
                self.overlay.as_image_copy(),
                overlay,
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(4 * w),
                    rows_per_image: Some(overlay_rows),
                },
                wgpu::Extent3d {
                    width: w,
                    height: overlay_rows,
                    depth_or_array_layers: 1,
                },
            );
        }
        overlay_rows
    }

    /// Records `shown` drawn into `target` by `pipeline` (`srgb`: the target encodes itself).
    fn draw(
        &self,
        shown: &Shown,
        pipeline: &wgpu::RenderPipeline,
        target: &wgpu::TextureView,
        srgb: bool,
    ) -> wgpu::CommandEncoder {
        let gpu = &*self.gpu;
        let [w, h] = self.size;
        let rgb = match shown.frame {
            FrameRadiance::Host(rgb) => {
                let flat: Vec<f32> = rgb.iter().flat_map(|c| c.to_array()).collect();
                gpu.write(&self.host_rgb, &flat);
                &self.host_rgb
            }
            FrameRadiance::Device { rgb, .. } => rgb,
        };
        let overlay_rows = self.upload_overlay(shown.overlay);
        let scale = shown.exposure.exp2().to_bits();
        let params = [w, h, overlay_rows, u32::from(srgb), scale, 0, 0, 0];
        let uniform = gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("show"),
                contents: bytemuck::cast_slice(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let overlay = self.overlay.create_view(&Default::default());
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("show"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: rgb.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&overlay),
                },
            ],
        });
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("show"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.draw(0..3, 0..1);
        }
        encoder
    }
}
