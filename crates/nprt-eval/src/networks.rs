//! The trained networks under evaluation (Neural PRT designs and Deep Shading): loading them
//! against the dataset, shading every test view, and the names rows get.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Result};
use glam::Vec3;
use nprt_net::Device;
use nprt_render::Relighter;
use nprt_scene::EnvMap;
use nprt_trace::{render_gbuffer, GBuffer};

use crate::error_analysis::Accumulator;
use crate::evaluate::{ms, EvalOptions};
use crate::method::{Family, MethodResult};
use crate::test_bench::TestBench;
use nprt_net::deep_shading::DeepShadingModel;

/// A network under evaluation and its folder.
pub enum Net {
    Nprt(Box<Relighter>, PathBuf),
    DeepShading(Box<DeepShadingModel>, PathBuf),
}

impl Net {
    pub fn family(&self) -> Family {
        match self {
            Net::Nprt(..) => Family::NeuralPrt,
            Net::DeepShading(..) => Family::DeepShading,
        }
    }

    fn kind_name(&self) -> String {
        match self {
            Net::Nprt(r, _) => format!("nprt-{}", r.file.config.design.name()),
            Net::DeepShading(..) => "deep-shading".into(),
        }
    }

    fn dir(&self) -> &Path {
        match self {
            Net::Nprt(_, d) | Net::DeepShading(_, d) => d,
        }
    }

    /// Transport parameters (without the encoder), as the paper counts them.
    fn params(&self) -> usize {
        match self {
            Net::Nprt(r, _) => r.file.transport_params,
            Net::DeepShading(d, _) => d.file.unet_params,
        }
    }

    /// Radiance of a G-buffer under a map, and (encoder, network) milliseconds.
    pub fn shade(
        &self,
        g: &GBuffer,
        w: usize,
        h: usize,
        map: &EnvMap,
        rotation: f32,
    ) -> (Vec<Vec3>, f64, f64) {
        match self {
            Net::Nprt(r, _) => {
                let t = Instant::now();
                let code = r.light_code(map, rotation);
                let enc = ms(t);
                let t = Instant::now();
                let rgb = r.shade(g, &code);
                (rgb, enc, ms(t))
            }
            Net::DeepShading(d, _) => {
                let t = Instant::now();
                let rgb = d.shade(g, w, h, map, rotation);
                (rgb, 0.0, ms(t))
            }
        }
    }
}

/// Loads every network `o` names, refusing one trained on another scene, and names each row
/// (two models of one design are told apart by their folders).
pub fn load_networks(
    o: &EvalOptions,
    device: &Device,
    dataset_hash: &str,
    scene_hash: &str,
) -> Result<Vec<(Net, String)>> {
    let mut nets = Vec::new();
    for dir in &o.models {
        let r = Relighter::load(dir, device)?;
        check_model(
            dir,
            dataset_hash,
            scene_hash,
            &r.file.scene_hash,
            &r.file.dataset_hash,
        )?;
        nets.push(Net::Nprt(Box::new(r), dir.clone()));
    }
    if let Some(dir) = &o.deep_shading {
        let d = DeepShadingModel::load(dir, device)?;
        check_model(
            dir,
            dataset_hash,
            scene_hash,
            &d.file.scene_hash,
            &d.file.dataset_hash,
        )?;
        nets.push(Net::DeepShading(Box::new(d), dir.clone()));
    }
    if nets.is_empty() {
        bail!("give at least one model to evaluate (--model)");
    }
    let names: Vec<String> = nets
        .iter()
        .map(|n| {
            match nets
                .iter()
                .filter(|m| m.kind_name() == n.kind_name())
                .count()
            {
                1 => n.kind_name(),
                _ => format!("{} ({})", n.kind_name(), n.dir().display()),
            }
        })
        .collect();
    Ok(nets.into_iter().zip(names).collect())
}

fn check_model(
    dir: &Path,
    dataset_hash: &str,
    scene_hash: &str,
    model_scene: &str,
    model_data: &str,
) -> Result<()> {
    if model_scene != scene_hash {
        bail!(
            "model '{}' was trained on another scene than the dataset's",
            dir.display()
        );
    }
    if model_data != dataset_hash {
        eprintln!(
            "note: model '{}' was trained on another dataset of the same scene; its test views may not be held out",
            dir.display()
        );
    }
    Ok(())
}

/// A model folder's validation loss against its training seconds; a loss.csv that cannot be
/// read costs the report this curve only.
fn validation_curve(dir: &Path, name: &str) -> Vec<(f64, f64)> {
    match nprt_net::curves::read_csv(&dir.join("loss.csv")) {
        Ok(rows) => rows
            .iter()
            .filter_map(|r| Some((r.seconds, r.val?)))
            .collect(),
        Err(e) => {
            eprintln!("warning: {e:#}; the report leaves out {name}'s validation curve");
            Vec::new()
        }
    }
}

/// Every network on every test view; its cost per view is the G-buffer, the encoder and the
/// network, as at run time.
pub fn run_networks(bench: &mut TestBench, nets: &[(Net, String)]) -> Vec<MethodResult> {
    let mut results = Vec::new();
    for (net, name) in nets {
        let mut acc = Accumulator::new(name, net.family(), Some(net.params()));
        let loss_png = net.dir().join("loss.png");
        acc.result.loss_png = loss_png.is_file().then_some(loss_png);
        acc.result.validation = validation_curve(net.dir(), name);
        for (k, v) in bench.views.iter().enumerate() {
            bench.bar.set_message(name.clone());
            let t = Instant::now();
            let g = render_gbuffer(bench.ts, &v.camera);
            let g_ms = ms(t);
            let (rgb, enc, net_ms) = net.shade(
                &g,
                v.width,
                v.height,
                &bench.maps[v.record.map],
                v.record.rotation_deg,
            );
            acc.add(v, &rgb, g_ms + enc + net_ms);
            bench.show(k, name, &rgb);
            bench.bar.inc(1);
        }
        results.push(acc.finish());
    }
    results
}
