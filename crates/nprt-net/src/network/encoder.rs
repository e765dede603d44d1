//! The light encoder F_L: a small CNN that turns a lat-long environment map into the light code ê.

use glam::Vec2;
use nprt_scene::envmap::{uv_to_direction, EnvMap};
use rayon::prelude::*;

use crate::encoding::map_norm::MapNorm;
use crate::init::Init;
use crate::network::activation::Activation;
use crate::network::conv::Conv;
use crate::network::dense::Dense;
use crate::network::mlp::Mlp;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// Convolution blocks of the paper's encoder.
pub const BLOCKS: usize = 5;
/// Channels of every convolution.
pub const CHANNELS: usize = 32;
/// Size of the light code ê.
pub const CODE_SIZE: usize = 64;

/// The widest encoder input: 8× the default. The dense layer after the blocks has W² weights,
/// and every view holds its W × W/2 map in training, so widths far beyond it (6400000 tried to
/// allocate 245 TB) can only fail.
pub const MAX_INPUT_WIDTH: usize = 1024;

/// The encoder's input width must halve cleanly through every block, and the height is half
/// the width.
pub fn check_input_width(width: usize) -> anyhow::Result<()> {
    let step = 2usize.pow(BLOCKS as u32 + 1);
    if width < step || !width.is_multiple_of(step) || width > MAX_INPUT_WIDTH {
        anyhow::bail!(
            "encoder input width {width} must be a multiple of {step} from {step} to {MAX_INPUT_WIDTH} (the map is W×W/2 and {BLOCKS} blocks halve it)"
        );
    }
    Ok(())
}

/// 5 × (3×3 conv with 32 channels, ReLU, skip connection, 2×2 max-pool), then one dense layer
/// to the 64-d code. The skip adds the block's input to the ReLU output; the first block's
/// 3-channel input is zero-padded to 32 channels for that sum, so the skips add no parameters.
/// Also (same shapes) its gradient. The CPU engine runs it (`cpu::light_encoder`).
#[derive(Clone, Debug, PartialEq)]
pub struct LightEncoder {
    pub convs: Vec<Conv>,
    pub to_code: Dense,
}

impl LightEncoder {
    pub fn new(init: &mut Init, width: usize) -> Self {
        let convs = (0..BLOCKS)
            .map(|i| Conv::new(init, if i == 0 { 3 } else { CHANNELS }, CHANNELS, 3))
            .collect();
        let flat = CHANNELS * (width >> BLOCKS) * (width >> (BLOCKS + 1));
        let mut to_code = Mlp::new(init, &[flat, CODE_SIZE], Activation::Relu);
        LightEncoder {
            convs,
            to_code: to_code.layers.remove(0),
        }
    }
}

impl Parameters for LightEncoder {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        self.convs.visit(&child(prefix, "convs"), f);
        self.to_code.visit(&child(prefix, "to_code"), f);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        self.convs.visit_mut(&child(prefix, "convs"), f);
        self.to_code.visit_mut(&child(prefix, "to_code"), f);
    }
}

/// How a map's normalised texels are held for the light model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Texels {
    /// log(1 + x), as the paper pre-processes them for its encoder.
    Log,
    /// As they are, for the linear design's basis, which must stay linear in the map.
    Linear,
}

/// An environment map prepared for the light model: box-filtered to W × W/2, divided by its
/// mean (over channels or per channel, [`MapNorm`]) and, for the paper's encoder, passed
/// through log(1 + x) ([`Texels`]).
///
/// Radiance is linear in the lighting, so the network predicts radiance for the normalised map
/// and the model multiplies each channel by `scale` to restore the absolute level.
#[derive(Clone, Debug)]
pub struct LightInput {
    /// Channel-major [3, W/2, W] values.
    pub pixels: Vec<f32>,
    /// What each channel of the map was divided by.
    pub scale: [f32; 3],
    /// W: the encoder input width.
    pub width: usize,
}

impl LightInput {
    /// The paper's: log(1 + x) of the normalised texels.
    pub fn new(map: &EnvMap, rotation_deg: f32, width: usize, norm: MapNorm) -> Self {
        Self::with_texels(map, rotation_deg, width, norm, Texels::Log)
    }

    pub fn with_texels(
        map: &EnvMap,
        rotation_deg: f32,
        width: usize,
        norm: MapNorm,
        texels: Texels,
    ) -> Self {
        let height = width / 2;
        let map = map.rotated_y(rotation_deg);
        // Enough sub-samples per encoder texel to cover every source texel it spans.
        let ss = map.width().div_ceil(width).max(2);
        let mut rgb = vec![glam::Vec3::ZERO; width * height];
        // In parallel: a 1024-wide map takes 64 lookups per texel, milliseconds on one core,
        // which a frame under a new lighting waits for.
        rgb.par_iter_mut().enumerate().for_each(|(i, out)| {
            let (x, y) = (i % width, i / width);
            for s in 0..ss * ss {
                let (sx, sy) = (s % ss, s / ss);
                let uv = Vec2::new(
                    (x as f32 + (sx as f32 + 0.5) / ss as f32) / width as f32,
                    (y as f32 + (sy as f32 + 0.5) / ss as f32) / height as f32,
                );
                *out += map.eval(uv_to_direction(uv));
            }
            *out /= (ss * ss) as f32;
        });
        // Summed in f64: an f32 running sum over a map with a sun drifts by 10⁻⁵ or more,
        // which the divisor, and every prediction with it, would carry.
        let mean = [0, 1, 2]
            .map(|k| (rgb.iter().map(|c| c[k] as f64).sum::<f64>() / rgb.len() as f64) as f32);
        let scale = norm.scale(mean);
        let mut pixels = vec![0.0; 3 * width * height];
        for (i, c) in rgb.iter().enumerate() {
            for k in 0..3 {
                let v = c[k] / scale[k];
                pixels[k * width * height + i] = match texels {
                    Texels::Log => v.ln_1p(),
                    Texels::Linear => v,
                };
            }
        }
        LightInput {
            pixels,
            scale,
            width,
        }
    }
}
