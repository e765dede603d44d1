//! A trained network's frames on the CPU engine ([`Shading`]): the light model on the host's
//! map input, what each track's networks make before the light enters kept per camera (ŝ, or a
//! linear track's transfer coefficients), and the rest per lighting.

use anyhow::{bail, Result};
use nprt_scene::EnvMap;

use super::transport::KeptRows;
use crate::encoding::map_norm::MapNorm;
use crate::network::encoder::LightInput;
use crate::network::nprt_net::NprtNet;
use crate::precision::Precision;
use crate::shading::Shading;

/// A model's networks on the CPU engine.
pub struct CpuShading {
    net: NprtNet,
    /// What each radiance channel is multiplied by besides the map's divisor.
    gain: [f32; 3],
    /// The encoder's input: its width and normalisation.
    encoder_width: usize,
    map_norm: MapNorm,
}

/// A lighting on the host: the code ê and what the map's channels were divided by.
pub struct HostCode {
    code: Vec<f32>,
    divisor: [f32; 3],
}

/// A camera's pixels on the host: their inputs and what a lighting change leaves of each track.
pub struct HostRows {
    features: Vec<f32>,
    kept: KeptRows,
}

impl CpuShading {
    pub fn new(net: NprtNet, gain: [f32; 3], encoder_width: usize, map_norm: MapNorm) -> Self {
        CpuShading {
            net,
            gain,
            encoder_width,
            map_norm,
        }
    }
}

impl Shading for CpuShading {
    type Code = HostCode;
    type Rows = HostRows;

    fn light_code(&self, map: &EnvMap, rotation_deg: f32) -> HostCode {
        let (width, norm, texels) = (self.encoder_width, self.map_norm, self.net.light.texels());
        let input = LightInput::with_texels(map, rotation_deg, width, norm, texels);
        HostCode {
            code: self
                .net
                .light
                .forward(&input.pixels, input.width)
                .codes()
                .to_vec(),
            divisor: input.scale,
        }
    }

    fn pixels(&self, features: &[f32]) -> HostRows {
        HostRows {
            kept: self.net.kept_rows(features),
            features: features.to_vec(),
        }
    }

    fn radiance(&self, rows: &HostRows, light: &HostCode) -> Vec<f32> {
        // Each channel: the map's divisor times the model's gain.
        let scale = std::array::from_fn(|k| light.divisor[k] * self.gain[k]);
        (self.net).radiance(&rows.features, &light.code, scale, Some(&rows.kept))
    }

    fn precision(&self) -> Precision {
        Precision::F32
    }

    fn set_precision(&mut self, precision: Precision) -> Result<()> {
        if precision == Precision::F16 {
            bail!("--precision f16 runs on the GPU kernels only (--device gpu or --device wgpu)");
        }
        Ok(())
    }

    fn describe(&self) -> String {
        "CPU engine".into()
    }

    fn flops_per_pixel(&self, transfer_known: bool) -> Option<f64> {
        Some(self.net.flops_per_pixel(transfer_known))
    }
}
