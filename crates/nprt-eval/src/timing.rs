//! The paper's Tables 3 and 4 on this machine: what each stage of one frame costs.

use std::time::Instant;

use anyhow::{bail, Result};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{render, render_gbuffer, GBuffer, RenderSettings, TraceScene};
use serde::{Deserialize, Serialize};

use crate::evaluate::ms;
use crate::networks::Net;

/// Rows of the timing table.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Timing {
    pub what: String,
    pub ms: f64,
}

/// The paper's Tables 3 and 4 on this machine: per-stage times of one frame at
/// `timing_res`², the median of three runs each.
pub fn time_table(
    timing_res: u32,
    ts: &TraceScene,
    camera: &Camera,
    map: &EnvMap,
    nets: &[(Net, String)],
    pt: &RenderSettings,
) -> Result<Vec<Timing>> {
    let camera = camera.with_resolution(timing_res, timing_res);
    let n = timing_res as usize;
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
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
    });
    for (net, name) in nets {
        let runs: Vec<(f64, f64)> = (0..3)
            .map(|_| {
                let (_, e, m) = net.shade(&g, n, n, map, 0.0);
                (e, m)
            })
            .collect();
        if let Net::Nprt(..) = net {
            rows.push(Timing {
                what: format!("{name}: encoder"),
                ms: median(runs.iter().map(|r| r.0).collect()),
            });
        }
        rows.push(Timing {
            what: format!("{name}: network"),
            ms: median(runs.iter().map(|r| r.1).collect()),
        });
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
    });
    if rows.iter().any(|r| !r.ms.is_finite()) {
        bail!("a timing was not finite");
    }
    Ok(rows)
}
