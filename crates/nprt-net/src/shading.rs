//! A trained network as frames run it, on whichever engine `--device` chose: a lighting's light
//! code once per lighting, a camera's pixels once per viewpoint (their inputs and what of the
//! network does not depend on the lighting), then radiance for each lighting. The CPU engine
//! (`cpu::CpuShading`, made by [`CpuEngine`]) and the GPU kernels (`gpu::GpuNetwork`, made by
//! `gpu::GpuKernels`) implement it; each names the types its light codes and pixels have, so
//! that one engine's cannot reach another's. A renderer resolves [`crate::Engine`] once into
//! one of the [`NetworkEngine`]s (the Deep Shading U-Net's [`UnetShading`] likewise, by
//! [`crate::Engine::unet`]); a frame's other stages (G-buffer, background, traced light) are
//! the renderer's.

use anyhow::Result;
use nprt_scene::EnvMap;

use crate::cpu::CpuShading;
use crate::model::folder::ModelFile;
use crate::network::encoder::LightInput;
use crate::network::nprt_net::NprtNet;
use crate::precision::Precision;

/// A trained NPRT network on an engine.
pub trait Shading: Send + Sync {
    /// What this engine makes of one lighting, held where it keeps it (on the GPU kernels,
    /// on the device).
    type Code: Send + Sync;

    /// A camera's pixels as this engine holds them (see [`Self::pixels`]).
    type Rows: Send + Sync;

    /// The light code of `map` turned by `rotation_deg` about +Y (on the GPU kernels, queued
    /// there and left on the device).
    fn light_code(&self, map: &EnvMap, rotation_deg: f32) -> Self::Code;

    /// A camera's foreground pixels from their network inputs (`rows × FEATURES`), with what
    /// does not depend on the lighting run once: a lighting change then runs only the rest.
    fn pixels(&self, features: &[f32]) -> Self::Rows;

    /// Radiance (`rows × 3`) of `px` under `light`: each channel times the map's divisor and
    /// the model's gain.
    fn radiance(&self, px: &Self::Rows, light: &Self::Code) -> Vec<f32>;

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
}

/// An engine a model's networks can be put on: its network type, made from a model's weights.
pub trait NetworkEngine {
    type Network: Shading;

    /// The trained network `net`, with `file`'s settings (its encoder's input and its gain).
    fn network(file: &ModelFile, net: NprtNet) -> Result<Self::Network>;
}

/// The CPU engine: networks on the host ([`crate::cpu`]).
pub struct CpuEngine;

impl NetworkEngine for CpuEngine {
    type Network = CpuShading;

    fn network(file: &ModelFile, net: NprtNet) -> Result<CpuShading> {
        let (width, norm) = (file.config.encoder_width, file.config.map_norm);
        Ok(CpuShading::new(net, file.output_gain(), width, norm))
    }
}

/// A trained Deep Shading U-Net on an engine.
pub trait UnetShading: Send + Sync {
    /// Radiance (3 × h × w) of a view's `features` (FEATURES × h × w) under the map `light`.
    fn radiance(&self, features: Vec<f32>, light: LightInput, size: (usize, usize)) -> Vec<f32>;
}
