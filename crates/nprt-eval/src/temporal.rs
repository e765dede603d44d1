//! Temporal stability: every method along a short camera path under changing lighting, frame
//! after frame, against path-traced references of the same frames. A still image hides what a
//! video shows: path tracing's noise and a denoiser's blotches change from frame to frame, and a
//! screen-space network may flicker as the view moves. The temporal error of a frame pair is the
//! mean, over pixels in the foreground of both frames and their channels, of
//! |(M_t − M_{t−1}) − (R_t − R_{t−1})|: the change of the method's frames that the reference's
//! change does not explain (zero for a method that returns the reference). The lighting changes
//! once, half-way, from one held-out map to another: a method that lags (a cache trained online)
//! shows it as a spike in its per-frame error there.

use glam::Vec3;
use nprt_net::Engine;
use nprt_render::oidn::Oidn;
use nprt_render::{CameraPath, DirectSampling};
use nprt_scene::{Camera, CameraVolume, EnvMap};
use nprt_trace::{render, render_gbuffer, CacheRead, GBuffer, RenderSettings, TraceScene};
use serde::{Deserialize, Serialize};

use std::time::Instant;

use anyhow::Result;

use crate::metrics::Metrics;
use crate::networks::{rows_of, Net};
use crate::nrc::{steps_within, Nrc, NrcSettings};
use crate::stopwatch::ms;

/// Share of the scene's camera sweep (`CameraPath::through_volume`, across the volume and back)
/// the frames cover: a slow move, as in a video.
const PATH_SPAN: f32 = 0.1;
/// Degrees each map turns about +Y over its half of the frames.
const SPIN_DEG: f32 = 15.0;
/// Frames shown around the lighting change in the report's strips.
pub const STRIP: usize = 4;

/// What the temporal evaluation is run on.
pub struct TemporalSetup<'a> {
    pub ts: &'a TraceScene<'a>,
    pub volume: &'a CameraVolume,
    /// The two maps: the first lights the first half of the frames, the second the rest.
    pub maps: [&'a EnvMap; 2],
    pub frames: usize,
    pub resolution: [u32; 2],
    /// The references' samples per pixel (in two halves of different seeds).
    pub reference_spp: u32,
    /// The dataset's path tracer (max depth, Russian roulette) at any spp and seed.
    pub tracer: &'a dyn Fn(u32, u64) -> RenderSettings,
    pub seed: u64,
    pub direct_spp: u32,
    /// The scene's bounds (the radiance cache's positions are normalised by them).
    pub bounds: [[f32; 3]; 2],
    /// Frames the warmed caches render (at the first frame) before the first one measured.
    pub nrc_warmup: usize,
    /// Where the caches train (the networks' engine).
    pub engine: Engine,
}

/// One method's frames along the path, scored against the references.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TemporalResult {
    pub name: String,
    /// Mean over frame pairs of [`temporal_error`].
    pub temporal_error: f64,
    /// Each consecutive pair's (frame t − 1 → t, t from 1).
    pub per_pair: Vec<f64>,
    /// Each frame's errors against its reference.
    pub per_frame: Vec<Metrics>,
    /// Mean milliseconds a frame cost on this machine (a network's G-buffer included; a
    /// cache's training included).
    #[serde(default)]
    pub ms_per_frame: f64,
}

/// The temporal evaluation's results.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Temporal {
    pub frames: usize,
    pub resolution: [u32; 2],
    pub reference_spp: u32,
    /// The first frame under the second map.
    pub change_at: usize,
    /// The maps' names, in order.
    pub maps: [String; 2],
    /// Frames the warmed caches rendered before the first.
    #[serde(default)]
    pub nrc_warmup: usize,
    /// How the caches ran: their settings (Adam steps per frame chosen to fit the budget) and
    /// the budget.
    #[serde(default)]
    pub nrc: Option<NrcBudget>,
    /// The references' own temporal error: their first halves of samples scored against the
    /// whole, a floor of noise under every method's figure.
    pub noise_floor: f64,
    pub methods: Vec<TemporalResult>,
    /// Frames around the lighting change, per method (reference first), for the report.
    #[serde(skip)]
    pub strips: Vec<(String, Vec<Vec<Vec3>>)>,
    /// The strip's foreground masks.
    #[serde(skip)]
    pub strip_masks: Vec<Vec<f32>>,
}

/// The temporal error of one frame pair: the mean over pixels in the foreground of both
/// frames, and over channels, of |(m_cur − m_prev) − (r_cur − r_prev)|.
pub fn temporal_error(
    [m_prev, m_cur]: [&[Vec3]; 2],
    [r_prev, r_cur]: [&[Vec3]; 2],
    [mask_prev, mask_cur]: [&[f32]; 2],
) -> f64 {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for i in (0..mask_cur.len()).filter(|&i| mask_prev[i] > 0.5 && mask_cur[i] > 0.5) {
        let d = (m_cur[i] - m_prev[i]) - (r_cur[i] - r_prev[i]);
        sum += d.abs().element_sum() as f64;
        n += 3;
    }
    sum / n.max(1) as f64
}

/// A frame of the path: its camera and lighting (map index and rotation).
struct PathFrame {
    camera: Camera,
    map: usize,
    rotation: f32,
}

impl TemporalSetup<'_> {
    /// The map lighting frame `f`, placed.
    fn lit(&self, f: &PathFrame) -> EnvMap {
        self.maps[f.map].rotated_y(f.rotation)
    }

    fn change_at(&self) -> usize {
        self.frames / 2
    }

    fn path(&self) -> Vec<PathFrame> {
        let path = CameraPath::through_volume(self.volume);
        let [w, h] = self.resolution;
        let last = (self.frames - 1).max(1) as f32;
        (0..self.frames)
            .map(|i| {
                let map = usize::from(i >= self.change_at());
                let first = [0, self.change_at()][map];
                let span = [self.change_at(), self.frames - self.change_at()][map];
                PathFrame {
                    camera: path.camera(PATH_SPAN * i as f32 / last, w, h),
                    map,
                    rotation: SPIN_DEG * (i - first) as f32 / span.max(1) as f32,
                }
            })
            .collect()
    }
}

/// Every method's frames along the path (the networks, path tracing at `spp` and, with
/// `oidn`, denoised, the radiance caches), scored against references. `on_frame` hears each
/// frame rendered.
pub fn run_temporal(
    setup: &TemporalSetup,
    nets: &[(Net, String)],
    path_tracing: (&str, u32),
    oidn: Option<&'static Oidn>,
    on_frame: &dyn Fn(),
) -> Result<Temporal> {
    let frames = setup.path();
    let mut t = Temporal {
        frames: setup.frames,
        resolution: setup.resolution,
        reference_spp: setup.reference_spp,
        change_at: setup.change_at(),
        maps: setup.maps.map(|m| m.name().to_string()),
        nrc_warmup: setup.nrc_warmup,
        ..Temporal::default()
    };
    let refs = references(setup, &frames, on_frame);
    let mut rows = network_rows(setup, &frames, &refs, nets, oidn, on_frame)?;
    // The caches' budget: the D/S frame's time (else the slowest network's).
    let budget = (rows.iter().find(|r| r.0 == "nprt-dsep"))
        .or_else(|| rows.iter().max_by(|a, b| a.2.total_cmp(&b.2)))
        .map(|r| r.2);
    let traced = traced_rows(setup, &frames, &refs, path_tracing, oidn, on_frame)?;
    rows.extend(traced);
    let (caches, nrc) = cache_rows(setup, &frames, budget, on_frame)?;
    rows.extend(caches);
    t.nrc = Some(nrc);
    let width = setup.resolution[0] as usize;
    let score =
        |name: &str, rgb: &[Vec<Vec3>]| score(name, rgb, &refs.whole, &refs.gbuffers, width);
    t.noise_floor = score("reference (half)", &refs.halves).temporal_error;
    t.keep_strip("reference", &refs.whole, &refs.gbuffers);
    for (name, rgb, ms_per_frame) in rows {
        t.methods.push(TemporalResult {
            ms_per_frame,
            ..score(&name, &rgb)
        });
        t.keep_strip(&name, &rgb, &refs.gbuffers);
    }
    Ok(t)
}

/// A method's name, its frames along the path and their mean cost in milliseconds.
type Row = (String, Vec<Vec<Vec3>>, f64);

/// The path's references (in two halves of different seeds: the whole, and the first half,
/// the floor) and G-buffers, with what a G-buffer cost.
struct References {
    whole: Vec<Vec<Vec3>>,
    halves: Vec<Vec<Vec3>>,
    gbuffers: Vec<GBuffer>,
    gbuffer_ms: f64,
}

fn references(setup: &TemporalSetup, frames: &[PathFrame], on_frame: &dyn Fn()) -> References {
    let half = (setup.reference_spp / 2).max(1);
    let mut r = References {
        whole: Vec::new(),
        halves: Vec::new(),
        gbuffers: Vec::new(),
        gbuffer_ms: 0.0,
    };
    for (i, f) in frames.iter().enumerate() {
        let map = setup.lit(f);
        let seed = |h: u64| setup.seed ^ 0x7e3a_0000 ^ (i as u64) << 8 ^ h;
        let a = render(setup.ts, &f.camera, &map, &(setup.tracer)(half, seed(1))).radiance;
        let b = render(setup.ts, &f.camera, &map, &(setup.tracer)(half, seed(2))).radiance;
        r.whole
            .push(a.iter().zip(&b).map(|(x, y)| (*x + *y) * 0.5).collect());
        r.halves.push(a);
        let t = Instant::now();
        r.gbuffers.push(render_gbuffer(setup.ts, &f.camera));
        r.gbuffer_ms += ms(t) / frames.len() as f64;
        on_frame();
    }
    r
}

/// Every network's frames (and, with `oidn`, those of a network that traces its direct light
/// with that light denoised), each costing its G-buffer too.
fn network_rows(
    setup: &TemporalSetup,
    frames: &[PathFrame],
    refs: &References,
    nets: &[(Net, String)],
    oidn: Option<&'static Oidn>,
    on_frame: &dyn Fn(),
) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    for (net, name) in nets {
        for (row, denoiser) in rows_of(net, name, oidn) {
            let mut rgb = Vec::new();
            let mut frame_ms = refs.gbuffer_ms;
            for (i, (f, g)) in frames.iter().zip(&refs.gbuffers).enumerate() {
                nprt_io::interrupt::check()?;
                let sampling = DirectSampling {
                    spp: setup.direct_spp,
                    seed: setup.seed ^ 0x7e3a_d1ec ^ i as u64,
                    denoiser,
                };
                let map = (setup.maps[f.map], f.rotation);
                let shaded = net.shade(setup.ts, &f.camera, g, map, sampling)?;
                frame_ms += shaded.total_ms() / frames.len() as f64;
                rgb.push(shaded.rgb);
                on_frame();
            }
            rows.push((row, rgb, frame_ms));
        }
    }
    Ok(rows)
}

/// Path tracing at `spp` as `pt_name`, fresh seeds every frame, and with `oidn` the same
/// denoised.
fn traced_rows(
    setup: &TemporalSetup,
    frames: &[PathFrame],
    refs: &References,
    (pt_name, spp): (&str, u32),
    oidn: Option<&'static Oidn>,
    on_frame: &dyn Fn(),
) -> Result<Vec<Row>> {
    let mut traced = Vec::new();
    let mut traced_ms = 0.0;
    for (i, f) in frames.iter().enumerate() {
        let seed = setup.seed ^ 0x7e3a_5eed ^ (i as u64) << 8;
        let (map, settings) = (setup.lit(f), (setup.tracer)(spp, seed));
        let start = Instant::now();
        traced.push(render(setup.ts, &f.camera, &map, &settings).radiance);
        traced_ms += ms(start) / frames.len() as f64;
        on_frame();
    }
    let mut rows = Vec::new();
    if let Some(oidn) = oidn {
        let (w, h) = (setup.resolution[0] as usize, setup.resolution[1] as usize);
        let start = Instant::now();
        let denoised = (traced.iter().zip(&refs.gbuffers))
            .map(|(f, g)| oidn.denoise_frame(f, g, w, h))
            .collect::<Result<Vec<_>>>()?;
        let denoise_ms = ms(start) / frames.len() as f64;
        rows.push((
            format!("{pt_name} + OIDN"),
            denoised,
            traced_ms + denoise_ms,
        ));
    }
    rows.insert(0, (pt_name.to_string(), traced, traced_ms));
    Ok(rows)
}

/// What the radiance caches were given: the frame budget they were held to (the D/S frame's
/// time, where there was one), what a frame's rendering and one training step measured, and
/// the settings that fit (the steps per frame).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NrcBudget {
    pub budget_ms: Option<f64>,
    pub render_ms: f64,
    pub step_ms: f64,
    pub settings: NrcSettings,
}

/// NRC and NRC-CACHE from a cold start, and each again warmed where `setup` asks, each
/// training as many steps per frame as fit `budget_ms` beside its rendering.
fn cache_rows(
    setup: &TemporalSetup,
    frames: &[PathFrame],
    budget_ms: Option<f64>,
    on_frame: &dyn Fn(),
) -> Result<(Vec<Row>, NrcBudget)> {
    let fit = fit_budget(setup, &frames[0], budget_ms)?;
    let warmups = match setup.nrc_warmup {
        0 => vec![0],
        n => vec![0, n],
    };
    let reads = [
        ("nrc", CacheRead::Spread),
        ("nrc-cache", CacheRead::FirstVertex),
    ];
    let mut rows = Vec::new();
    for (name, read) in reads {
        for &warmup in &warmups {
            let row = match warmup {
                0 => name.to_string(),
                n => format!("{name} (warmed {n} frames)"),
            };
            let settings = NrcSettings {
                read,
                ..fit.settings
            };
            let (rgb, frame_ms) = run_cache(setup, frames, settings, warmup, on_frame)?;
            rows.push((row, rgb, frame_ms));
        }
    }
    Ok((rows, fit))
}

/// Times a cache's frame at the path's first frame, without training and with four steps,
/// and fits the steps per frame to `budget_ms` (four without one). A throwaway cache is timed:
/// the measured ones start cold.
fn fit_budget(
    setup: &TemporalSetup,
    first: &PathFrame,
    budget_ms: Option<f64>,
) -> Result<NrcBudget> {
    let path = (setup.tracer)(1, 0).path();
    let map = setup.lit(first);
    let mut settings = NrcSettings::new(CacheRead::Spread);
    let timed = |steps: usize| {
        let settings = NrcSettings { steps, ..settings };
        let mut nrc = Nrc::new(settings, &setup.bounds, setup.seed, setup.engine)?;
        // The first frame of a cold cache warms nothing up but the caches of the machine.
        nrc.frame(setup.ts, &first.camera, &map, &path);
        let start = Instant::now();
        nrc.frame(setup.ts, &first.camera, &map, &path);
        Ok::<f64, anyhow::Error>(ms(start))
    };
    let render_ms = timed(0)?;
    let step_ms = ((timed(4)? - render_ms) / 4.0).max(1e-3);
    if let Some(budget) = budget_ms {
        settings.steps = steps_within(budget, render_ms, step_ms);
    }
    Ok(NrcBudget {
        budget_ms,
        render_ms,
        step_ms,
        settings,
    })
}

/// A radiance cache with `settings`, trained online frame after frame along `frames`
/// from a cold start, after `warmup` frames at the first one; its frames and their mean cost.
fn run_cache(
    setup: &TemporalSetup,
    frames: &[PathFrame],
    settings: NrcSettings,
    warmup: usize,
    on_frame: &dyn Fn(),
) -> Result<(Vec<Vec<Vec3>>, f64)> {
    let path = (setup.tracer)(1, 0).path();
    let seed = setup.seed ^ 0x7e3a_ca4e ^ u64::from(settings.read == CacheRead::FirstVertex);
    let mut nrc = Nrc::new(settings, &setup.bounds, seed, setup.engine)?;
    let first = setup.lit(&frames[0]);
    for _ in 0..warmup {
        nprt_io::interrupt::check()?;
        nrc.frame(setup.ts, &frames[0].camera, &first, &path);
    }
    let mut rgb = Vec::new();
    let mut total_ms = 0.0;
    for f in frames {
        nprt_io::interrupt::check()?;
        let map = setup.lit(f);
        let start = Instant::now();
        rgb.push(nrc.frame(setup.ts, &f.camera, &map, &path));
        total_ms += ms(start);
        on_frame();
    }
    Ok((rgb, total_ms / frames.len() as f64))
}

/// A method's frames scored against the references: per pair and per frame.
fn score(
    name: &str,
    rgb: &[Vec<Vec3>],
    references: &[Vec<Vec3>],
    gbuffers: &[GBuffer],
    width: usize,
) -> TemporalResult {
    let per_pair: Vec<f64> = (1..rgb.len())
        .map(|t| {
            temporal_error(
                [&rgb[t - 1], &rgb[t]],
                [&references[t - 1], &references[t]],
                [&gbuffers[t - 1].mask, &gbuffers[t].mask],
            )
        })
        .collect();
    let per_frame = (rgb.iter().zip(references).zip(gbuffers))
        .map(|((m, r), g)| Metrics::compute(m, r, &g.mask, width))
        .collect();
    TemporalResult {
        name: name.into(),
        temporal_error: per_pair.iter().sum::<f64>() / per_pair.len().max(1) as f64,
        per_pair,
        per_frame,
        ms_per_frame: 0.0,
    }
}

impl TemporalResult {
    /// Each frame's L1 error.
    pub fn per_frame_l1(&self) -> Vec<f64> {
        self.per_frame.iter().map(|m| m.l1).collect()
    }
}

impl Temporal {
    /// The strip's frames of `rgb`: [`STRIP`] around the lighting change.
    fn strip_range(&self) -> std::ops::Range<usize> {
        let first = self.change_at.saturating_sub(STRIP / 2);
        first..(first + STRIP).min(self.frames)
    }

    fn keep_strip(&mut self, name: &str, rgb: &[Vec<Vec3>], gbuffers: &[GBuffer]) {
        let range = self.strip_range();
        if self.strip_masks.is_empty() {
            self.strip_masks = gbuffers[range.clone()]
                .iter()
                .map(|g| g.mask.clone())
                .collect();
        }
        self.strips.push((name.into(), rgb[range].to_vec()));
    }

    /// The frames the strips show, from.
    pub fn strip_first(&self) -> usize {
        self.strip_range().start
    }

    pub fn method(&self, name: &str) -> Option<&TemporalResult> {
        self.methods.iter().find(|m| m.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frames(values: &[f32]) -> Vec<Vec<Vec3>> {
        values.iter().map(|&v| vec![Vec3::splat(v); 4]).collect()
    }

    #[test]
    fn the_reference_has_no_temporal_error_and_a_flickering_stand_in_has() {
        let mask = vec![1.0; 4];
        let reference = frames(&[1.0, 1.5, 2.0]);
        let pair = |m: &[Vec<Vec3>], t: usize| {
            temporal_error(
                [&m[t - 1], &m[t]],
                [&reference[t - 1], &reference[t]],
                [&mask, &mask],
            )
        };
        assert_eq!(pair(&reference, 1), 0.0);
        assert_eq!(pair(&reference, 2), 0.0);
        // A constant offset (a biased but stable method) does not flicker.
        let biased = frames(&[1.2, 1.7, 2.2]);
        assert!(pair(&biased, 1).abs() < 1e-6);
        // Alternating ±0.1 around the reference: each pair changes by 0.2 more than it.
        let flicker = frames(&[1.1, 1.4, 2.1]);
        assert!((pair(&flicker, 1) - 0.2).abs() < 1e-6);
        assert!((pair(&flicker, 2) - 0.2).abs() < 1e-6);
        // A frozen method misses the reference's whole change.
        let frozen = frames(&[1.0, 1.0, 1.0]);
        assert!((pair(&frozen, 2) - 0.5).abs() < 1e-6);
    }

    #[test]
    fn only_pixels_in_both_foregrounds_count() {
        let m = [vec![Vec3::ZERO, Vec3::ONE], vec![Vec3::ONE, Vec3::ONE]];
        let r = [vec![Vec3::ZERO; 2], vec![Vec3::ZERO; 2]];
        let masks = [vec![0.0, 1.0], vec![1.0, 1.0]];
        // Pixel 0 changed by 1 but left the background: it does not count.
        let e = temporal_error([&m[0], &m[1]], [&r[0], &r[1]], [&masks[0], &masks[1]]);
        assert_eq!(e, 0.0);
    }
}
