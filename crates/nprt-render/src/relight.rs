//! The run-time network: light code once per lighting change, transport on foreground pixels.

use std::path::Path;

use anyhow::Result;
use glam::{Vec2, Vec3};
use nprt_net::burn::tensor::{Tensor, TensorData};
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
}

/// What the encoder made of one lighting: the 64-d code ê and the map's mean.
#[derive(Clone)]
pub struct LightCode {
    code: Tensor<2>,
    scale: f32,
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
        Ok(Relighter {
            file,
            net,
            device: device.clone(),
        })
    }

    /// Encodes `map` rotated by `rotation_deg` about +Y.
    pub fn light_code(&self, map: &EnvMap, rotation_deg: f32) -> LightCode {
        let input = LightInput::new(map, rotation_deg, self.file.config.encoder_width);
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
        let fg: Vec<usize> = (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5).collect();
        let mut out = vec![Vec3::ZERO; g.mask.len()];
        for chunk in fg.chunks(CHUNK) {
            let features: Vec<f32> = chunk
                .par_iter()
                .flat_map_iter(|&i| gbuffer_features(&self.file.bounds, g, i))
                .collect();
            let n = chunk.len();
            let f = Tensor::from_data(TensorData::new(features, [n, FEATURES]), &self.device);
            let code = light.code.clone().expand([n, light.code.dims()[1]]);
            let scale = Tensor::full([n, 1], light.scale, &self.device);
            let rgb = self.net.shade(f, code, scale).into_data();
            let rgb = rgb.as_slice::<f32>().expect("f32 network output");
            for (k, &i) in chunk.iter().enumerate() {
                out[i] = Vec3::from_slice(&rgb[3 * k..3 * k + 3]);
            }
        }
        out
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
