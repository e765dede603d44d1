//! The path-tracing baselines: at 5 spp and at the time of the slowest design, each also
//! denoised by Open Image Denoise when it is installed.

use std::time::Instant;

use anyhow::Result;
use glam::Vec3;
use nprt_render::oidn::Oidn;
use nprt_trace::render;

use crate::error_analysis::Accumulator;
use crate::method::{Family, MethodResult};
use crate::stopwatch::ms;
use crate::test_bench::TestBench;

/// A path-traced baseline's results and its frames (the denoiser's input).
pub struct Traced {
    pub result: MethodResult,
    pub frames: Vec<Vec<Vec3>>,
}

/// Path tracing of every test view at `spp`, timed per view; `salt` keeps the seeds of
/// different sample counts apart.
pub fn run_path_tracing(bench: &mut TestBench, name: &str, spp: u32, salt: u64) -> Traced {
    let mut acc = Accumulator::new(name, Family::PathTracing, None);
    let mut frames = Vec::new();
    for (k, v) in bench.views.iter().enumerate() {
        bench.bar.set_message(format!("path tracing {spp} spp"));
        let map = bench.lighting(v);
        let t = Instant::now();
        let f = render(
            bench.ts,
            &v.camera,
            &map,
            &bench.path_tracer(spp, v.record.seed ^ bench.seed ^ salt),
        );
        acc.add(v, &f.radiance, ms(t));
        bench.show(k, name, &f.radiance);
        frames.push(f.radiance);
        bench.bar.inc(1);
    }
    Traced {
        result: acc.finish(),
        frames,
    }
}

/// The sample count that costs what `budget_ms` per view buys, from 5-spp path tracing's cost.
pub fn equal_time_spp(pt5: &MethodResult, budget_ms: f64) -> u32 {
    ((budget_ms / (pt5.ms_per_view / 5.0)).round() as u32).max(1)
}

/// `base` denoised by OIDN (RT filter, HDR, albedo and normal auxiliaries); its cost is the
/// path tracing's plus the denoiser's.
pub fn run_denoised(bench: &mut TestBench, oidn: &Oidn, base: &Traced) -> Result<MethodResult> {
    let name = format!("{} + OIDN", base.result.name);
    let mut acc = Accumulator::new(&name, Family::Denoised, None);
    for (k, (v, f)) in bench.views.iter().zip(&base.frames).enumerate() {
        let t = Instant::now();
        let d = oidn.denoise_frame(f, &v.gbuffer, v.width, v.height)?;
        acc.add(v, &d, base.result.ms_per_view + ms(t));
        bench.show(k, &name, &d);
    }
    Ok(acc.finish())
}
