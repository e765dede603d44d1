//! The paper's Tables 3 and 4 on this machine: what each stage of one frame costs.

use std::time::Instant;

use anyhow::{bail, Result};
use glam::Vec3;
use nprt_net::median;
use nprt_render::DirectSampling;
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{render, render_gbuffer, GBuffer, TraceScene};
use serde::{Deserialize, Serialize};

use crate::networks::{Net, Shaded};
use crate::stopwatch::ms;
use crate::test_bench::TestBench;

/// Rows of the timing table.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Timing {
    pub what: String,
    pub ms: f64,
    /// Achieved f32 GFLOP/s of the dense layers, for the networks on the CPU engine.
    #[serde(default)]
    pub gflops: Option<f64>,
}

/// The paper's Tables 3 and 4 on this machine: per-stage times of one frame of the bench's
/// first test view at `timing_res`², the median of three runs each; for Neural PRT designs
/// also a lighting change under a still camera, which runs only the shading networks, and the
/// direct light of those that trace it as `direct` says, also denoised when it names a
/// denoiser.
pub fn time_table(
    bench: &TestBench,
    timing_res: u32,
    nets: &[(Net, String)],
    direct: DirectSampling,
) -> Result<Vec<Timing>> {
    let view = &bench.views[0];
    let (ts, map, pt) = (bench.ts, bench.map(view), &bench.path_tracer(5, bench.seed));
    let camera = view.camera.with_resolution(timing_res, timing_res);
    let mut g = GBuffer::default();
    let mut rows = vec![Timing {
        what: "G-buffer (primary rays)".into(),
        ms: median_of_runs(|| g = render_gbuffer(ts, &camera)),
        gflops: None,
    }];
    let frame = TimedFrame {
        ts,
        camera: &camera,
        map,
        g: &g,
        direct,
    };
    for (net, name) in nets {
        rows.extend(frame.network_rows(net, name)?);
    }
    rows.push(Timing {
        what: "path tracing, 5 spp".into(),
        ms: median_of_runs(|| {
            render(ts, &camera, map, pt);
        }),
        gflops: None,
    });
    if rows.iter().any(|r| !r.ms.is_finite()) {
        bail!("a timing was not finite");
    }
    Ok(rows)
}

/// Runs each timing takes; the median is reported.
const RUNS: usize = 3;

/// The median of [`RUNS`] timed calls of `f`, in milliseconds.
fn median_of_runs(mut f: impl FnMut()) -> f64 {
    let mut runs = Vec::new();
    for _ in 0..RUNS {
        let t = Instant::now();
        f();
        runs.push(ms(t));
        // A stop requested (nprt_io::interrupt): no further runs; the evaluation's check after
        // its timings ends it.
        if nprt_io::interrupt::requested() {
            break;
        }
    }
    median(runs)
}

/// The frame every network is timed on.
struct TimedFrame<'a> {
    ts: &'a TraceScene<'a>,
    camera: &'a Camera,
    map: &'a EnvMap,
    g: &'a GBuffer,
    direct: DirectSampling,
}

impl TimedFrame<'_> {
    /// One network's rows: its network time, and for a Neural PRT design its encoder, the
    /// traced direct light (raw and denoised) of a design that traces it, and a lighting change
    /// under a still camera.
    fn network_rows(&self, net: &Net, name: &str) -> Result<Vec<Timing>> {
        let (ts, camera, map, g, direct) = (self.ts, self.camera, self.map, self.g, self.direct);
        let raw = DirectSampling {
            denoiser: None,
            ..direct
        };
        let runs = (0..RUNS)
            .map(|_| net.shade(ts, camera, g, (map, 0.0), raw))
            .collect::<Result<Vec<Shaded>>>()?;
        let network_ms = median(runs.iter().map(|r| r.network_ms).collect());
        let row = |what: String, ms: f64, gflops: Option<f64>| Timing { what, ms, gflops };
        let Net::Nprt(r, _) = net else {
            return Ok(vec![row(format!("{name}: network"), network_ms, None)]);
        };
        let foreground = g.mask.iter().filter(|&&m| m > 0.5).count() as f64;
        let gflops = |transfer_known, ms: f64| {
            r.flops_per_pixel(transfer_known)
                .map(|f| f * foreground / (ms * 1e6))
        };
        let mut rows = vec![
            row(
                format!("{name}: encoder"),
                median(runs.iter().map(|r| r.encoder_ms).collect()),
                None,
            ),
            row(
                format!("{name}: network"),
                network_ms,
                gflops(false, network_ms),
            ),
        ];
        if r.traces_direct() {
            rows.push(row(
                format!("{name}: traced direct light, {} spp", direct.spp),
                median(runs.iter().map(|r| r.direct_ms).collect()),
                None,
            ));
            if direct.denoiser.is_some() {
                // Only the completion runs again: the network's part is the same either way.
                let mut failed = None;
                let denoised = median_of_runs(|| {
                    let mut rgb = vec![Vec3::ZERO; g.mask.len()];
                    if let Err(e) = r.complete(ts, camera, map, g, direct, &mut rgb) {
                        failed = Some(e);
                    }
                });
                if let Some(e) = failed {
                    return Err(e);
                }
                rows.push(row(
                    format!(
                        "{name}: traced direct light, {} spp, denoised by OIDN",
                        direct.spp
                    ),
                    denoised,
                    None,
                ));
            }
        }
        if r.file.config.design.has_transfer() {
            let still = r.still(g, map, 0.0);
            let relight_ms = median_of_runs(|| {
                still.relight();
            });
            rows.push(row(
                format!(
                    "{name}: network, lighting change under a still camera ({:.1}× faster)",
                    network_ms / relight_ms
                ),
                relight_ms,
                gflops(true, relight_ms),
            ));
        }
        Ok(rows)
    }
}
