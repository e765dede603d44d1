//! The Deep Shading baseline's network (Nalbach et al. 2017): a U-Net on G-buffer images with
//! the light encoder's code added at its bottleneck. Widths are chosen for about the parameter
//! count of the Neural PRT designs (≈200 K without the encoder). The CPU engine runs it
//! (`cpu::unet`).

use crate::encoding::features::FEATURES;
use crate::init::Init;
use crate::network::activation::Activation;
use crate::network::conv::Conv;
use crate::network::dense::Dense;
use crate::network::encoder::{LightEncoder, CODE_SIZE};
use crate::network::mlp::Mlp;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// Channels of the encoder levels (full, ½, ¼ resolution) and of the ⅛-resolution bottleneck.
pub const WIDTHS: [usize; 4] = [16, 32, 64, 64];
/// Resolution levels above the bottleneck: images are padded to multiples of 2^LEVELS.
pub const LEVELS: usize = 3;

/// The U-Net, or (same shapes) its gradient.
#[derive(Clone, Debug, PartialEq)]
pub struct DeepShading {
    pub light: LightEncoder,
    /// Two 3×3 convolutions per encoder level.
    pub down: Vec<Conv>,
    pub bottleneck: Vec<Conv>,
    /// The light code as a per-channel offset of the bottleneck.
    pub code: Dense,
    /// One 3×3 convolution per decoder level, on [upsampled, skip].
    pub up: Vec<Conv>,
    /// 1×1 to the log-radiance.
    pub out: Conv,
}

impl DeepShading {
    pub fn new(init: &mut Init, encoder_width: usize) -> Self {
        let light = LightEncoder::new(init, encoder_width);
        let mut down = Vec::new();
        let mut c_in = FEATURES;
        for &w in &WIDTHS[..LEVELS] {
            down.push(Conv::new(init, c_in, w, 3));
            down.push(Conv::new(init, w, w, 3));
            c_in = w;
        }
        let b = WIDTHS[LEVELS];
        let bottleneck = vec![Conv::new(init, WIDTHS[2], b, 3), Conv::new(init, b, b, 3)];
        let code = Mlp::new(init, &[CODE_SIZE, b], Activation::Relu)
            .layers
            .remove(0);
        let up = vec![
            Conv::new(init, b + WIDTHS[2], WIDTHS[1], 3),
            Conv::new(init, WIDTHS[1] + WIDTHS[1], WIDTHS[0], 3),
            Conv::new(init, WIDTHS[0] + WIDTHS[0], WIDTHS[0], 3),
        ];
        DeepShading {
            light,
            down,
            bottleneck,
            code,
            up,
            out: Conv::new(init, WIDTHS[0], 3, 1),
        }
    }

    /// Parameters without the light encoder (comparable to the designs' transport counts).
    pub fn unet_params(&self) -> usize {
        self.num_params() - self.light.num_params()
    }

    /// Adds `log_level` to the output convolution's bias (see `NprtNet::shift_output_level`).
    pub fn shift_output_level(mut self, log_level: f32) -> Self {
        self.out.bias.iter_mut().for_each(|b| *b += log_level);
        self
    }
}

impl Parameters for DeepShading {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        self.light.visit(&child(prefix, "light"), f);
        self.down.visit(&child(prefix, "down"), f);
        self.bottleneck.visit(&child(prefix, "bottleneck"), f);
        self.code.visit(&child(prefix, "code"), f);
        self.up.visit(&child(prefix, "up"), f);
        self.out.visit(&child(prefix, "out"), f);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        self.light.visit_mut(&child(prefix, "light"), f);
        self.down.visit_mut(&child(prefix, "down"), f);
        self.bottleneck.visit_mut(&child(prefix, "bottleneck"), f);
        self.code.visit_mut(&child(prefix, "code"), f);
        self.up.visit_mut(&child(prefix, "up"), f);
        self.out.visit_mut(&child(prefix, "out"), f);
    }
}
