//! A frame's work on one engine, in that engine's types: its networks (a [`Shading`]) and the
//! stages beside them (a [`KeptStages`] of that network: G-buffer, traced light, and what stays
//! on the device), so that a light code or a camera's pixels one engine made are only ever
//! handed back to it. [`crate::Relighter`] holds one of
//! these, resolved once from the `--device` engine; this file holds what a frame does with it.

use std::time::Instant;

use anyhow::Result;
use glam::Vec3;
use nprt_net::{gbuffer_features, ModelFile, Shading, FEATURES};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{GBuffer, TraceScene};
use rayon::prelude::*;

use crate::frame_stages::{
    background, DirectSampling, FrameRadiance, KeptPixels, KeptStages, Rows,
};
use crate::frame_timings::FrameTimings;

/// A model's networks on an engine, and the frame's other stages beside them.
pub(crate) struct OnEngine<N: Shading, S: KeptStages<N>> {
    pub net: N,
    pub stages: S,
}

/// A G-buffer's foreground pixels on the networks (`rows`, with what of the networks does not
/// depend on the lighting: all a still camera needs to relight), of `count` in all.
pub(crate) struct Foreground<R> {
    count: usize,
    pixels: Vec<usize>,
    rows: R,
}

/// A camera's pixels: the foreground on the networks, or every pixel kept on the device.
type Pixels<N, S> = Rows<Foreground<<N as Shading>::Rows>, <S as KeptStages<N>>::Kept>;

/// What consecutive frames on one engine keep: the last camera's G-buffer and pixels, and the
/// last lighting's code under its key `K`.
pub(crate) struct Kept<N: Shading, S: KeptStages<N>, K> {
    still: Option<(Camera, GBuffer, Pixels<N, S>)>,
    light: Option<(K, N::Code)>,
}

impl<N: Shading, S: KeptStages<N>, K> Default for Kept<N, S, K> {
    fn default() -> Self {
        Kept {
            still: None,
            light: None,
        }
    }
}

impl<N: Shading, S: KeptStages<N>, K> Kept<N, S, K> {
    /// Foreground pixels of the kept G-buffer (none before a frame).
    pub fn foreground(&self) -> usize {
        match &self.still {
            None => 0,
            Some((_, _, Rows::Networks(px))) => px.pixels.len(),
            Some((camera, _, Rows::Kept(_))) => (camera.width * camera.height) as usize,
        }
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

impl<N: Shading, S: KeptStages<N>> OnEngine<N, S> {
    /// See [`crate::Relighter::complete`].
    #[allow(clippy::too_many_arguments)]
    pub fn complete(
        &self,
        file: &ModelFile,
        ts: &TraceScene,
        camera: &Camera,
        map: &EnvMap,
        g: &GBuffer,
        sampling: DirectSampling,
        rgb: &mut [Vec3],
    ) -> Result<()> {
        if file.config.direct.is_learned() {
            background(camera, map, &g.mask, rgb);
            return Ok(());
        }
        let rays = (sampling.spp, sampling.seed);
        let mut direct = self.stages.traced_direct(ts, camera, map, rays)?;
        if let Some(oidn) = sampling.denoiser {
            let (w, h) = (camera.width as usize, camera.height as usize);
            direct = oidn.denoise_frame(&direct, g, w, h)?;
        }
        rgb.par_iter_mut().zip(direct).for_each(|(c, d)| *c += d);
        Ok(())
    }

    /// See [`crate::Relighter::frame_shown`]; `kept` is what the last frame on this engine
    /// left.
    #[allow(clippy::too_many_arguments)]
    pub fn frame_shown<K: PartialEq>(
        &self,
        file: &ModelFile,
        kept: &mut Kept<N, S, K>,
        ts: &TraceScene,
        camera: &Camera,
        (map, rotation_deg, key): (&EnvMap, f32, K),
        sampling: DirectSampling,
        keep: bool,
    ) -> Result<(FrameRadiance, FrameTimings)> {
        let mut t = FrameTimings::default();
        let moved = !matches!(&kept.still, Some((c, _, _)) if c == camera);
        let code = match kept.light.take() {
            Some((k, code)) if k == key => code,
            _ => {
                let clock = Instant::now();
                let code = self.net.light_code(map, rotation_deg);
                // On the GPU kernels the code is only queued: before a new viewpoint's stages,
                // which wait for the queue one by one, it is waited for, so that the G-buffer
                // is not charged with it. A lighting change alone does not wait.
                if moved {
                    self.net.settle()?;
                }
                t.encoder_ms = ms(clock);
                code
            }
        };
        let (g, px) = match kept.still.take() {
            Some((c, g, px)) if c == *camera => (g, px),
            _ => match self.kept_pixels(file, ts, camera, &sampling, &mut t)? {
                Some(px) => (GBuffer::default(), px),
                None => {
                    let clock = Instant::now();
                    let g = self.stages.gbuffer(ts, camera)?;
                    t.gbuffer_ms = ms(clock);
                    let clock = Instant::now();
                    let px = self.foreground(&file.bounds, &g);
                    t.network_ms = ms(clock);
                    (g, Rows::Networks(px))
                }
            },
        };
        let placed = map.rotated_y(rotation_deg);
        let clock = Instant::now();
        let shown = match &px {
            Rows::Kept(rows) => {
                let direct =
                    (!file.config.direct.is_learned()).then_some((sampling.spp, sampling.seed));
                let (shown, direct_ms) =
                    (self.stages).kept_frame(&self.net, ts, rows, &code, &placed, direct, keep)?;
                t.network_ms += ms(clock) - direct_ms;
                t.direct_ms = direct_ms;
                shown
            }
            Rows::Networks(px) => {
                let mut rgb = self.relight(px, &code);
                t.network_ms += ms(clock);
                let clock = Instant::now();
                self.complete(file, ts, camera, &placed, &g, sampling, &mut rgb)?;
                t.direct_ms = ms(clock);
                FrameRadiance::Host(rgb)
            }
        };
        kept.light = Some((key, code));
        kept.still = Some((camera.clone(), g, px));
        Ok((shown, t))
    }

    /// A camera's pixels with the G-buffer left on the device, where the stages can and the
    /// frame needs nothing on the host (traced light to denoise: OIDN runs on the host); the
    /// G-buffer's and the networks' times into `t`.
    fn kept_pixels(
        &self,
        file: &ModelFile,
        ts: &TraceScene,
        camera: &Camera,
        sampling: &DirectSampling,
        t: &mut FrameTimings,
    ) -> Result<Option<Pixels<N, S>>> {
        if !file.config.direct.is_learned() && sampling.denoiser.is_some() {
            return Ok(None);
        }
        let kept = (self.stages).kept_pixels(&self.net, ts, camera, &file.bounds)?;
        let Some(KeptPixels {
            rows,
            gbuffer_ms,
            network_ms,
        }) = kept
        else {
            return Ok(None);
        };
        (t.gbuffer_ms, t.network_ms) = (gbuffer_ms, network_ms);
        Ok(Some(Rows::Kept(rows)))
    }

    /// The network inputs of `g`'s foreground pixels (positions normalised by `bounds`) run
    /// through what of the networks does not depend on the lighting, so that
    /// [`Self::relight`] under each further lighting runs only the shading networks.
    pub fn foreground(&self, bounds: &[[f32; 3]; 2], g: &GBuffer) -> Foreground<N::Rows> {
        let foreground: Vec<usize> = (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5).collect();
        let mut features = vec![0.0; foreground.len() * FEATURES];
        features
            .par_chunks_mut(FEATURES)
            .zip(&foreground)
            .for_each(|(f, &i)| f.copy_from_slice(&gbuffer_features(bounds, g, i)));
        Foreground {
            count: g.mask.len(),
            rows: self.net.pixels(&features),
            pixels: foreground,
        }
    }

    /// Radiance of every pixel of `px` (made by [`Self::foreground`]) under `light`;
    /// background pixels are zero.
    pub fn relight(&self, px: &Foreground<N::Rows>, light: &N::Code) -> Vec<Vec3> {
        let rgb = self.net.radiance(&px.rows, light);
        let mut out = vec![Vec3::ZERO; px.count];
        for (k, &i) in px.pixels.iter().enumerate() {
            out[i] = Vec3::from_slice(&rgb[3 * k..3 * k + 3]);
        }
        out
    }

    /// The GPU time of each kernel of a lighting change of the pixels `kept` holds, under the
    /// lighting it holds; None before a frame.
    #[cfg(feature = "gpu")]
    pub fn profile_relight<K>(
        &self,
        kept: &Kept<N, S, K>,
    ) -> Result<Option<Vec<nprt_gpu::KernelTime>>> {
        let (Some((_, _, px)), Some((_, light))) = (&kept.still, &kept.light) else {
            return Ok(None);
        };
        let rows = match px {
            Rows::Networks(px) => Rows::Networks(&px.rows),
            Rows::Kept(rows) => Rows::Kept(rows),
        };
        (self.stages).profile(&self.net, rows, light).map(Some)
    }
}
