//! The run-time network: light code once per lighting change, transport on foreground pixels,
//! and for a still camera the light-independent part (the transfer networks' ŝ) kept between
//! lighting changes.

use std::path::Path;

use anyhow::Result;
use glam::{Vec2, Vec3};
use nprt_net::burn::tensor::{Tensor, TensorData};
use nprt_net::cpu::{self, HostTransport, TransferCodes};
use nprt_net::gbuffer_features;
use nprt_net::{load_model, Device, LightInput, ModelFile, NprtNet, FEATURES};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::GBuffer;
use rayon::prelude::*;

/// Pixels per network call: large enough to amortise dispatch, small enough to bound memory.
const CHUNK: usize = 65_536;

/// A trained model ready to shade G-buffers.
pub struct Relighter {
    pub file: ModelFile,
    net: NprtNet,
    device: Device,
    /// The transport networks on the CPU engine, where it applies.
    host: Option<HostTransport>,
}

/// What the encoder made of one lighting: the 64-d code ê and what the map's channels were
/// divided by.
#[derive(Clone)]
pub struct LightCode {
    code: Tensor<2>,
    scale: [f32; 3],
}

/// A G-buffer's foreground pixels as network inputs, and what of the network does not depend
/// on the lighting: all a still camera needs to relight.
pub struct Pixels {
    count: usize,
    foreground: Vec<usize>,
    features: Vec<f32>,
    transfer: Option<TransferCodes>,
}

/// Milliseconds spent in each stage of one frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimings {
    pub gbuffer_ms: f64,
    pub encoder_ms: f64,
    pub network_ms: f64,
}

impl FrameTimings {
    pub fn total_ms(&self) -> f64 {
        self.gbuffer_ms + self.encoder_ms + self.network_ms
    }
}

impl Relighter {
    pub fn load(dir: &Path, device: &Device) -> Result<Self> {
        let (file, net) = load_model(dir, device)?;
        let host = cpu::applies(&net, device).then(|| HostTransport::from_net(&net));
        Ok(Relighter {
            file,
            net,
            device: device.clone(),
            host,
        })
    }

    /// Encodes `map` rotated by `rotation_deg` about +Y.
    pub fn light_code(&self, map: &EnvMap, rotation_deg: f32) -> LightCode {
        let config = &self.file.config;
        let input = LightInput::new(map, rotation_deg, config.encoder_width, config.map_norm);
        let w = input.width;
        let pixels = Tensor::from_data(
            TensorData::new(input.pixels, [1, 3, w / 2, w]),
            &self.device,
        );
        LightCode {
            code: self.net.encoder.forward(pixels),
            scale: input.scale,
        }
    }

    /// Radiance of every pixel of `g` under `light`; background pixels are zero (see
    /// [`background`]).
    pub fn shade(&self, g: &GBuffer, light: &LightCode) -> Vec<Vec3> {
        self.relight(&self.pixels(g), light)
    }

    /// The network inputs of `g`'s foreground pixels and, on the CPU engine, the transfer
    /// networks' outputs (same work as running them inline), so that [`Self::relight`] under
    /// each further lighting runs only the shading networks.
    pub fn pixels(&self, g: &GBuffer) -> Pixels {
        let foreground: Vec<usize> = (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5).collect();
        let features: Vec<f32> = foreground
            .par_iter()
            .flat_map_iter(|&i| gbuffer_features(&self.file.bounds, g, i))
            .collect();
        let transfer = self.host.as_ref().map(|h| h.transfer_codes(&features));
        Pixels {
            count: g.mask.len(),
            foreground,
            features,
            transfer,
        }
    }

    /// Floating-point operations of the dense layers per foreground pixel, for a frame from a
    /// new viewpoint or (`transfer_known`) a lighting change under a still camera; None off the
    /// CPU engine.
    pub fn flops_per_pixel(&self, transfer_known: bool) -> Option<f64> {
        self.host
            .as_ref()
            .map(|h| h.flops_per_pixel(transfer_known))
    }

    /// Radiance of every pixel under `light`; background pixels are zero.
    pub fn relight(&self, px: &Pixels, light: &LightCode) -> Vec<Vec3> {
        let rgb = match &self.host {
            Some(host) => {
                let code = cpu::host_values(light.code.clone().into_data());
                host.radiance(&px.features, &code, light.scale, px.transfer.as_ref())
            }
            None => self.burn_radiance(&px.features, light),
        };
        let mut out = vec![Vec3::ZERO; px.count];
        for (k, &i) in px.foreground.iter().enumerate() {
            out[i] = Vec3::from_slice(&rgb[3 * k..3 * k + 3]);
        }
        out
    }

    /// Radiance (`n × 3`) of feature rows through burn, in chunks of one fixed shape: a GPU
    /// compiles and tunes kernels per shape (on an H100 the first frame takes about 1 s, later
    /// ones 8 ms at 256²), so the tail is padded rather than given a new length every frame.
    fn burn_radiance(&self, features: &[f32], light: &LightCode) -> Vec<f32> {
        let rows = features.len() / FEATURES;
        let mut rgb = Vec::with_capacity(rows * 3);
        let code = light.code.clone().expand([CHUNK, light.code.dims()[1]]);
        let scale = Tensor::from_data(
            TensorData::new(light.scale.repeat(CHUNK), [CHUNK, 3]),
            &self.device,
        );
        for chunk in features.chunks(CHUNK * FEATURES) {
            let mut padded = chunk.to_vec();
            padded.resize(CHUNK * FEATURES, 0.0);
            let f = Tensor::from_data(TensorData::new(padded, [CHUNK, FEATURES]), &self.device);
            let out = cpu::host_values(self.net.shade(f, code.clone(), scale.clone()).into_data());
            rgb.extend_from_slice(&out[..chunk.len() / FEATURES * 3]);
        }
        rgb
    }
}

/// Fills background pixels (mask 0) with the map seen through the pixel centre.
pub fn background(camera: &Camera, map: &EnvMap, mask: &[f32], rgb: &mut [Vec3]) {
    let w = camera.width as usize;
    rgb.par_iter_mut().enumerate().for_each(|(i, c)| {
        if mask[i] <= 0.5 {
            let (_, d) = camera.ray(Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5));
            *c = map.eval(d);
        }
    });
}
