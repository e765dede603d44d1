//! The light model on the CPU engine: the encoder's pass (`cpu::light_encoder`) or a basis'
//! projection, forward over a batch's maps and backward into the model's gradient.

use rayon::prelude::*;

use super::light_encoder::EncoderPass;
use crate::network::light_basis::LightBasis;
use crate::network::light_model::LightModel;
use crate::parameters::Parameters;

/// A batch's light codes (`views × code size`) and what backward needs.
pub enum LightPass {
    Encoder(EncoderPass),
    Basis(Vec<f32>),
}

impl LightPass {
    pub fn codes(&self) -> &[f32] {
        match self {
            LightPass::Encoder(p) => &p.codes,
            LightPass::Basis(codes) => codes,
        }
    }
}

impl LightModel {
    /// The codes of `lights` (views × [3, W/2, W], channel-major, as a training `Batch` keeps
    /// them, with the texels [`LightModel::texels`] asks for) for a map width `width`.
    pub fn forward(&self, lights: &[f32], width: usize) -> LightPass {
        match self {
            LightModel::Encoder(e) => LightPass::Encoder(e.forward(lights, width)),
            LightModel::Basis(b) => LightPass::Basis(b.project(lights)),
        }
    }

    /// The gradient of every parameter from the gradient at the codes `d_codes`.
    pub fn backward(&self, pass: &LightPass, lights: &[f32], d_codes: &[f32]) -> LightModel {
        match (self, pass) {
            (LightModel::Encoder(e), LightPass::Encoder(p)) => {
                LightModel::Encoder(e.backward(p, d_codes))
            }
            (LightModel::Basis(b), _) => LightModel::Basis(b.backward(lights, d_codes)),
            (LightModel::Encoder(_), LightPass::Basis(_)) => {
                unreachable!("an encoder's pass comes from its forward")
            }
        }
    }
}

impl LightBasis {
    /// Each function times its texel's solid angle, K × texels: P as it multiplies a map.
    fn weighted(&self) -> Vec<f32> {
        let solid = self.texel_solid_angles();
        let mut p = self.functions.clone();
        p.par_chunks_mut(solid.len()).for_each(|row| {
            row.iter_mut().zip(&solid).for_each(|(v, s)| *v *= s);
        });
        p
    }

    /// The codes of `maps` (views × [3, W/2, W]): per view, coefficient k of channel c at
    /// k·3 + c, the sum over texels of function k × solid angle × the map's channel c.
    pub fn project(&self, maps: &[f32]) -> Vec<f32> {
        let (k, texels) = (self.size(), self.width * self.width / 2);
        let p = self.weighted();
        maps.par_chunks(3 * texels)
            .flat_map_iter(|map| {
                let mut code = vec![0.0f32; 3 * k];
                for (j, row) in p.chunks_exact(texels).enumerate() {
                    for (c, channel) in map.chunks_exact(texels).enumerate() {
                        // Summed in f64: a sun is one texel among thousands.
                        let dot: f64 = (row.iter().zip(channel)).map(|(a, b)| (a * b) as f64).sum();
                        code[j * 3 + c] = dot as f32;
                    }
                }
                code
            })
            .collect()
    }

    /// The gradient of the functions (zero for spherical harmonics, which are not trained)
    /// from the gradient `d_codes` at the codes of `maps`.
    pub fn backward(&self, maps: &[f32], d_codes: &[f32]) -> LightBasis {
        let mut grad = self.zeros_like();
        if !self.choice.is_learned() {
            return grad;
        }
        let (k, solid) = (self.size(), self.texel_solid_angles());
        let texels = solid.len();
        grad.functions
            .par_chunks_mut(texels)
            .enumerate()
            .for_each(|(j, out)| {
                for (map, d) in maps
                    .chunks_exact(3 * texels)
                    .zip(d_codes.chunks_exact(3 * k))
                {
                    for (c, channel) in map.chunks_exact(texels).enumerate() {
                        let g = d[j * 3 + c];
                        out.iter_mut().zip(channel).for_each(|(o, m)| *o += g * m);
                    }
                }
                out.iter_mut().zip(&solid).for_each(|(v, s)| *v *= s);
            });
        grad
    }
}
