//! The paper's Tables 3 and 4 on this machine: what each stage of one frame costs.

use std::time::Instant;

use anyhow::{bail, Result};
use glam::Vec3;
use nprt_net::median;
use nprt_render::DirectSampling;
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{render, render_gbuffer, GBuffer, RenderSettings, TraceScene};
use serde::{Deserialize, Serialize};

use crate::evaluate::ms;
use crate::networks::{Net, Shaded};

/// Rows of the timing table.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Timing {
    pub what: String,
    pub ms: f64,
    /// Achieved f32 GFLOP/s of the dense layers, for the networks on the CPU engine.
    #[serde(default)]
    pub gflops: Option<f64>,
}

/// The paper's Tables 3 and 4 on this machine: per-stage times of one frame at
/// `timing_res`², the median of three runs each; for Neural PRT designs also a lighting change
/// under a still camera, which runs only the shading networks, and the direct light of those
/// that trace it as `direct` says, also denoised when it names a denoiser.
pub fn time_table(
    timing_res: u32,
    ts: &TraceScene,
    camera: &Camera,
    map: &EnvMap,
    nets: &[(Net, String)],
    pt: &RenderSettings,
    direct: DirectSampling,
) -> Result<Vec<Timing>> {
    let camera = camera.with_resolution(timing_res, timing_res);
    let raw = DirectSampling {
        denoiser: None,
        ..direct
    };
    let mut rows = Vec::new();
    let mut g = GBuffer::default();
    let gb = median(
        (0..3)
            .map(|_| {
                let t = Instant::now();
                g = render_gbuffer(ts, &camera);
                ms(t)
            })
            .collect(),
    );
    rows.push(Timing {
        what: "G-buffer (primary rays)".into(),
        ms: gb,
        gflops: None,
    });
    for (net, name) in nets {
        let runs = (0..3)
            .map(|_| net.shade(ts, &camera, &g, (map, 0.0), raw))
            .collect::<Result<Vec<Shaded>>>()?;
        let network_ms = median(runs.iter().map(|r| r.network_ms).collect());
        let Net::Nprt(r, _) = net else {
            rows.push(Timing {
                what: format!("{name}: network"),
                ms: network_ms,
                gflops: None,
            });
            continue;
        };
        let foreground = g.mask.iter().filter(|&&m| m > 0.5).count() as f64;
        let gflops = |transfer_known, ms: f64| {
            r.flops_per_pixel(transfer_known)
                .map(|f| f * foreground / (ms * 1e6))
        };
        rows.push(Timing {
            what: format!("{name}: encoder"),
            ms: median(runs.iter().map(|r| r.encoder_ms).collect()),
            gflops: None,
        });
        rows.push(Timing {
            what: format!("{name}: network"),
            ms: network_ms,
            gflops: gflops(false, network_ms),
        });
        if r.traces_direct() {
            rows.push(Timing {
                what: format!("{name}: traced direct light, {} spp", direct.spp),
                ms: median(runs.iter().map(|r| r.direct_ms).collect()),
                gflops: None,
            });
            if direct.denoiser.is_some() {
                // Only the completion runs again: the network's part is the same either way.
                let denoised = (0..3)
                    .map(|_| {
                        let mut rgb = vec![Vec3::ZERO; g.mask.len()];
                        let t = Instant::now();
                        r.complete(ts, &camera, map, &g, direct, &mut rgb)?;
                        Ok(ms(t))
                    })
                    .collect::<Result<Vec<f64>>>()?;
                rows.push(Timing {
                    what: format!(
                        "{name}: traced direct light, {} spp, denoised by OIDN",
                        direct.spp
                    ),
                    ms: median(denoised),
                    gflops: None,
                });
            }
        }
        if r.file.config.design != nprt_net::Design::Baseline {
            let px = r.pixels(&g);
            let code = r.light_code(map, 0.0);
            let relight_ms = median(
                (0..3)
                    .map(|_| {
                        let t = Instant::now();
                        r.relight(&px, &code);
                        ms(t)
                    })
                    .collect(),
            );
            rows.push(Timing {
                what: format!(
                    "{name}: network, lighting change under a still camera ({:.1}× faster)",
                    network_ms / relight_ms
                ),
                ms: relight_ms,
                gflops: gflops(true, relight_ms),
            });
        }
    }
    let pt_ms = median(
        (0..3)
            .map(|_| {
                let t = Instant::now();
                render(ts, &camera, map, pt);
                ms(t)
            })
            .collect(),
    );
    rows.push(Timing {
        what: "path tracing, 5 spp".into(),
        ms: pt_ms,
        gflops: None,
    });
    if rows.iter().any(|r| !r.ms.is_finite()) {
        bail!("a timing was not finite");
    }
    Ok(rows)
}
