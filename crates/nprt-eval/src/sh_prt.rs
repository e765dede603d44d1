//! The SH PRT baselines: per-pixel transport with 25 and 9 spherical-harmonics coefficients
//! per channel, path-traced once per (fixed) test view, then relit by dot products.

use std::time::Instant;

use crate::error_analysis::Accumulator;
use crate::method::{Family, MethodResult};
use crate::sh::ShTransport;
use crate::stopwatch::ms;
use crate::test_bench::TestBench;

/// SH PRT 9 and 25 on every test view; `sh_spp` paths per pixel for the transport.
pub fn run_sh_prt(bench: &mut TestBench, sh_spp: u32) -> Vec<MethodResult> {
    let mut sh = [
        Accumulator::new("sh-prt-9", Family::ShPrt, None),
        Accumulator::new("sh-prt-25", Family::ShPrt, None),
    ];
    let mut pre_ms = 0.0;
    for (k, v) in bench.views.iter().enumerate() {
        // A stop requested: the evaluation's check after this stage ends it.
        if nprt_io::interrupt::requested() {
            break;
        }
        bench
            .bar
            .set_message(format!("SH transport, {sh_spp} paths per pixel"));
        let t = Instant::now();
        let t25 = ShTransport::precompute(
            bench.ts,
            &v.camera,
            5,
            &bench.path_tracer(sh_spp, v.record.seed ^ bench.seed ^ 0x5eed_0525),
        );
        pre_ms += ms(t);
        let map = bench.lighting(v);
        for (acc, transport) in sh.iter_mut().zip([t25.truncated(3), t25]) {
            let t = Instant::now();
            let rgb = transport.shade(&map);
            acc.add(v, &rgb, ms(t));
            let name = acc.result.name.clone();
            bench.show(k, &name, &rgb);
        }
        bench.bar.inc(1);
    }
    let views = bench.views.len().max(1) as f64;
    sh.into_iter()
        .map(|acc| {
            let mut r = acc.finish();
            r.precompute_ms = Some(pre_ms / views);
            r.note =
                format!("transport path-traced at {sh_spp} paths per pixel per view (fixed view)");
            r
        })
        .collect()
}
