//! The trained networks under evaluation (Neural PRT designs and Deep Shading): loading them
//! against the dataset, shading every test view, and the names rows get.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Result};
use glam::Vec3;
use nprt_net::{Engine, ModelConfig};
use nprt_render::oidn::Oidn;
use nprt_render::{DirectSampling, Relighter};
use nprt_scene::{Camera, EnvMap};
use nprt_trace::{render_gbuffer, GBuffer, TraceScene};

use crate::error_analysis::Accumulator;
use crate::eval_options::EvalOptions;
use crate::method::{Family, MethodResult};
use crate::stopwatch::ms;
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

    /// Whether the network leaves its direct light to the tracer.
    pub fn traces_direct(&self) -> bool {
        matches!(self, Net::Nprt(r, _) if r.traces_direct())
    }

    fn kind_name(&self) -> String {
        match self {
            Net::Nprt(r, _) => row_name(&r.file.config),
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

    /// A frame's radiance from its G-buffer `g` under `map` rotated by `rotation` degrees,
    /// with what each stage cost; a model that traces direct light traces it as `sampling`
    /// says.
    pub fn shade(
        &self,
        ts: &TraceScene,
        camera: &Camera,
        g: &GBuffer,
        (map, rotation): (&EnvMap, f32),
        sampling: DirectSampling,
    ) -> Result<Shaded> {
        match self {
            Net::Nprt(r, _) => {
                let (mut rgb, shaded) = r.shade(g, (map, rotation))?;
                let t = Instant::now();
                if r.traces_direct() {
                    let placed = map.rotated_y(rotation);
                    r.complete(ts, camera, &placed, g, sampling, &mut rgb)?;
                }
                Ok(Shaded {
                    rgb,
                    encoder_ms: shaded.encoder_ms,
                    network_ms: shaded.network_ms,
                    direct_ms: ms(t),
                })
            }
            Net::DeepShading(d, _) => {
                let t = Instant::now();
                let rgb = d.shade(
                    g,
                    camera.width as usize,
                    camera.height as usize,
                    map,
                    rotation,
                );
                Ok(Shaded {
                    rgb,
                    network_ms: ms(t),
                    ..Shaded::default()
                })
            }
        }
    }
}

/// The row a Neural PRT model of `config` gets in a report (unless two share it).
pub fn row_name(config: &ModelConfig) -> String {
    format!("nprt-{}", config.label())
}

/// A network's frame and what its stages cost, in milliseconds.
#[derive(Default)]
pub struct Shaded {
    /// Radiance of every pixel; background pixels zero unless direct light was traced.
    pub rgb: Vec<Vec3>,
    pub encoder_ms: f64,
    pub network_ms: f64,
    /// Tracing the direct light (models that leave it to the tracer; otherwise zero).
    pub direct_ms: f64,
}

impl Shaded {
    pub fn total_ms(&self) -> f64 {
        self.encoder_ms + self.network_ms + self.direct_ms
    }
}

/// Loads every network `o` names, refusing one trained on another scene, and names each row
/// (two models of one design are told apart by their folders).
pub fn load_networks(
    o: &EvalOptions,
    engine: Engine,
    dataset_hash: &str,
    scene_hash: &str,
) -> Result<Vec<(Net, String)>> {
    let mut nets = Vec::new();
    for dir in &o.models {
        let r = Relighter::load(dir, engine)?;
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
        let d = DeepShadingModel::load(dir, engine)?;
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
    match nprt_net::training::loss_curves::read_csv(&dir.join("loss.csv")) {
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

/// The rows a network gives: its own, and, with `oidn`, for a model that traces its direct
/// light, one with that light denoised ("NAME + OIDN"); each with its denoiser.
pub fn rows_of(
    net: &Net,
    name: &str,
    oidn: Option<&'static Oidn>,
) -> Vec<(String, Option<&'static Oidn>)> {
    let mut rows = vec![(name.to_string(), None)];
    if let Some(o) = oidn.filter(|_| net.traces_direct()) {
        rows.push((format!("{name} + OIDN"), Some(o)));
    }
    rows
}

/// Every network on every test view; its cost per view is the G-buffer, the encoder, the
/// network and any traced direct light, as at run time. A model that traces direct light runs
/// a second time with that light denoised when `oidn` is given (a row of its own, "+ OIDN").
pub fn run_networks(
    bench: &mut TestBench,
    nets: &[(Net, String)],
    oidn: Option<&'static Oidn>,
) -> Result<Vec<MethodResult>> {
    let mut results = Vec::new();
    for (net, name) in nets {
        for (row, denoiser) in rows_of(net, name, oidn) {
            let family = match denoiser {
                None => net.family(),
                Some(_) => Family::Denoised,
            };
            let mut acc = Accumulator::new(&row, family, Some(net.params()));
            if denoiser.is_none() {
                let loss_png = net.dir().join("loss.png");
                acc.result.loss_png = loss_png.is_file().then_some(loss_png);
                acc.result.validation = validation_curve(net.dir(), name);
            }
            if net.traces_direct() {
                acc.result.note = format!(
                    "direct light traced at {} spp per view{}, in its time; its validation loss is on the indirect light, which is all its network learns",
                    bench.direct_spp,
                    if denoiser.is_some() { " and denoised" } else { "" }
                );
            }
            for (k, v) in bench.views.iter().enumerate() {
                bench.bar.set_message(row.clone());
                let t = Instant::now();
                let g = render_gbuffer(bench.ts, &v.camera);
                let g_ms = ms(t);
                let sampling = DirectSampling {
                    spp: bench.direct_spp,
                    seed: v.record.seed ^ bench.seed ^ 0x5eed_d1ec,
                    denoiser,
                };
                let shaded = net.shade(
                    bench.ts,
                    &v.camera,
                    &g,
                    (bench.map(v), v.record.rotation_deg),
                    sampling,
                )?;
                acc.add(v, &shaded.rgb, g_ms + shaded.total_ms());
                bench.show(k, &row, &shaded.rgb);
                bench.bar.inc(1);
            }
            results.push(acc.finish());
        }
    }
    Ok(results)
}
