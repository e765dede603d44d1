//! A trained network as frames run it, on whichever engine `--device` chose: a lighting's light
//! code once per lighting, a camera's pixels once per viewpoint (their inputs and what of the
//! network does not depend on the lighting), then radiance for each lighting. The CPU engine
//! (`cpu::CpuShading`) and the GPU kernels (`gpu::GpuNetwork`) implement it, and
//! [`crate::Engine::network`] is the one place that picks between them (the Deep Shading
//! U-Net's [`UnetShading`] likewise, by [`crate::Engine::unet`]); a frame's other stages
//! (G-buffer, background, traced light) are the renderer's.

use std::any::Any;
use std::sync::Arc;

use anyhow::Result;
use nprt_scene::EnvMap;

use crate::network::encoder::LightInput;
use crate::precision::Precision;

/// A trained NPRT network on an engine.
pub trait Shading: Send + Sync {
    /// The light code of `map` turned by `rotation_deg` about +Y, as this engine holds it (on
    /// the GPU kernels, queued there and left on the device).
    fn light_code(&self, map: &EnvMap, rotation_deg: f32) -> LightCode;

    /// A camera's foreground pixels from their network inputs (`rows × FEATURES`), with what
    /// does not depend on the lighting run once: a lighting change then runs only the rest.
    fn pixels(&self, features: &[f32]) -> PixelRows;

    /// Radiance (`rows × 3`) of `px` under `light`: each channel times the map's divisor and
    /// the model's gain.
    fn radiance(&self, px: &PixelRows, light: &LightCode) -> Vec<f32>;

    /// The precision the dense layers run in.
    fn precision(&self) -> Precision;

    /// Runs the dense layers in `precision` from now on (pixels made before must be made
    /// again); f16 needs the GPU kernels and an adapter with f16 in shaders.
    fn set_precision(&mut self, precision: Precision) -> Result<()>;

    /// Where the networks run, for reports: "CPU engine" or "GPU kernels on ADAPTER".
    fn describe(&self) -> String;

    /// Floating-point operations of the dense layers per pixel, for a new viewpoint or
    /// (`transfer_known`) a lighting change under a still camera; None where not counted.
    fn flops_per_pixel(&self, _transfer_known: bool) -> Option<f64> {
        None
    }

    /// Waits for the work this engine queued (a light code: [`Self::light_code`] does not
    /// wait), so that a stage timed after is not charged with it.
    fn settle(&self) -> Result<()> {
        Ok(())
    }

    /// How many times the host has waited for this engine's queue so far (None off the GPU).
    fn host_waits(&self) -> Option<u64> {
        None
    }

    /// The engine's own type, for a renderer whose frame stages run beside it (on the GPU, the
    /// device network whose pixels a rasterised G-buffer feeds).
    fn as_any(&self) -> &dyn Any;
}

/// A trained Deep Shading U-Net on an engine.
pub trait UnetShading: Send + Sync {
    /// Radiance (3 × h × w) of a view's `features` (FEATURES × h × w) under the map `light`.
    fn radiance(&self, features: Vec<f32>, light: LightInput, size: (usize, usize)) -> Vec<f32>;
}

/// What an engine made of one lighting, held where that engine keeps it.
#[derive(Clone)]
pub struct LightCode(Arc<dyn Any + Send + Sync>);

/// A camera's pixels as an engine holds them (see [`Shading::pixels`]).
pub struct PixelRows(Box<dyn Any + Send + Sync>);

impl LightCode {
    pub fn new<T: Any + Send + Sync>(code: T) -> Self {
        LightCode(Arc::new(code))
    }

    /// The code as the engine of type `T` made it; None for another engine's.
    pub fn get<T: Any>(&self) -> Option<&T> {
        self.0.downcast_ref()
    }
}

impl PixelRows {
    pub fn new<T: Any + Send + Sync>(rows: T) -> Self {
        PixelRows(Box::new(rows))
    }

    /// The pixels as the engine of type `T` made them; None for another engine's.
    pub fn get<T: Any>(&self) -> Option<&T> {
        self.0.downcast_ref()
    }
}

/// `what` made by another engine than the one asked to use it: a programming error, as one
/// renderer holds one engine.
pub(crate) fn foreign(what: &str) -> ! {
    panic!("{what} made by another engine than the one using it")
}
