//! Where a traced design's error lives (`nprt eval --oracles`): each half of its image set
//! beside the reference's own other half. A model that traces its direct light adds that
//! light to its network's indirect light; two oracle rows score each part alone, the other
//! part taken from the reference (the test view's `direct.*` channels and their complement,
//! from the same paths):
//!
//! - "NAME, reference direct": the network's indirect light plus the reference's direct light,
//!   the error the network alone leaves;
//! - "NAME, reference indirect": the traced direct light (denoised where OIDN is there, as the
//!   model's best row) plus the reference's indirect light, the error the rays alone leave.
//!
//! They are measurements, not methods: nothing at run time has the reference's light, so they
//! carry no time and no equal-time peer.

use anyhow::Result;
use glam::Vec3;
use nprt_render::oidn::Oidn;
use nprt_render::DirectSampling;
use nprt_trace::render_gbuffer;

use crate::error_analysis::Accumulator;
use crate::method::{Family, MethodResult};
use crate::networks::Net;
use crate::test_bench::TestBench;

/// The two oracle rows of each network of `nets` that traces its direct light, over every test
/// view.
pub fn run_oracles(
    bench: &mut TestBench,
    nets: &[(Net, String)],
    oidn: Option<&'static Oidn>,
) -> Result<Vec<MethodResult>> {
    let mut rows = Vec::new();
    for (net, name) in nets {
        rows.extend(oracles_of(bench, net, name, oidn)?);
    }
    Ok(rows)
}

/// The two oracle rows of `net` (named `name`); none for a network that learns all its light.
fn oracles_of(
    bench: &mut TestBench,
    net: &Net,
    name: &str,
    oidn: Option<&'static Oidn>,
) -> Result<Vec<MethodResult>> {
    let Net::Nprt(r, _) = net else {
        return Ok(Vec::new());
    };
    if !r.traces_direct() {
        return Ok(Vec::new());
    }
    let denoised = if oidn.is_some() { ", denoised" } else { "" };
    let mut rays = Accumulator::new(&format!("{name}, reference indirect"), Family::Oracle, None);
    rays.result.note = format!(
        "oracle: the traced direct light ({} spp{denoised}) plus the reference's indirect light",
        bench.direct_spp
    );
    let mut network = Accumulator::new(&format!("{name}, reference direct"), Family::Oracle, None);
    network.result.note =
        "oracle: the network's indirect light plus the reference's direct light".into();
    for (k, v) in bench.views.iter().enumerate() {
        bench.bar.set_message(format!("{name}, oracles"));
        let g = render_gbuffer(bench.ts, &v.camera);
        let map = bench.map(v);
        let (mut rgb, _) = r.shade(&g, (map, v.record.rotation_deg))?;
        for (c, d) in rgb.iter_mut().zip(&v.direct) {
            *c += *d;
        }
        network.add(v, &rgb, 0.0);
        bench.show(k, &network.result.name, &rgb);
        // The reference's indirect light: its radiance less its direct part, from the same
        // paths (never below zero but for rounding).
        let mut rgb: Vec<Vec3> = (v.radiance.iter().zip(&v.direct))
            .map(|(l, d)| (*l - *d).max(Vec3::ZERO))
            .collect();
        let sampling = DirectSampling {
            spp: bench.direct_spp,
            // The model's own rows' seed: the same rays, so the row differs from the model's
            // only by the light the reference supplies.
            seed: v.record.seed ^ bench.seed ^ 0x5eed_d1ec,
            denoiser: oidn,
        };
        r.complete(
            bench.ts,
            &v.camera,
            &bench.lighting(v),
            &g,
            sampling,
            &mut rgb,
        )?;
        rays.add(v, &rgb, 0.0);
        bench.show(k, &rays.result.name, &rgb);
        bench.bar.inc(1);
    }
    Ok(vec![network.finish(), rays.finish()])
}
