//! `nprt export`: a trained model in the form an engine runs it. The frame path's WGSL kernels
//! as the viewer runs them, validated and translated to GLSL (4.30 compute) and HLSL (shader
//! model 5.1) by naga, with the half-precision ones (`--precision f16`) where naga can
//! translate them; every weight, little-endian f32, in one `weights.bin`, and the transport
//! networks' weights again as f16 in the half-precision kernels' layout, `weights_f16.bin`;
//! and `export.json`, which says where each tensor lies, how the networks are wired and how a
//! frame runs them (docs/export.md).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use nprt_net::encoding::hash_grid;
use nprt_net::network::dense::Dense;
use nprt_net::network::mlp::Mlp;
use nprt_net::{gbuffer_features, load_model, LightEncoder, LightModel, NprtNet, FEATURES};
use nprt_trace::{render_gbuffer, TraceScene};
use serde_json::{json, Value};

use nprt_gpu::KernelSource;
use nprt_net::gpu::kernels::{ENCODER_BLOCK_THREADS, GEMM_TILE};
use nprt_net::gpu::{half_weight_bits, pad16};

use super::kernels::{sources, HALF_SOURCES};
use crate::{CameraPath, ExampleView, Relighter};

/// Version of the export's layout, bumped whenever a reader would read it differently.
pub const EXPORT_VERSION: u32 = 7;

/// What an export wrote.
pub struct ExportSummary {
    pub files: Vec<PathBuf>,
    /// Weights written, in f32 values.
    pub weights: usize,
    /// Why no worked example was written, if none was.
    pub no_example: Option<String>,
}

/// The worked example's page and script, copied into every export.
const EXAMPLE_PAGE: [(&str, &str); 2] = [
    ("example/index.html", include_str!("example/index.html")),
    ("example/relight.js", include_str!("example/relight.js")),
];

/// The weights in file order, each tensor recorded in `export.json` by name, offset (in f32
/// values) and shape; and the transport networks' weights as f16 in the half-precision
/// layout, recorded the same way (offsets in f16 values).
#[derive(Default)]
struct WeightFile {
    values: Vec<f32>,
    tensors: Vec<Value>,
    halves: Vec<u16>,
    half_tensors: Vec<Value>,
}

impl WeightFile {
    fn add(&mut self, name: &str, shape: &[usize], values: &[f32]) -> Value {
        assert_eq!(
            shape.iter().product::<usize>(),
            values.len(),
            "{name}'s shape"
        );
        let offset = self.values.len();
        self.values.extend_from_slice(values);
        self.tensors
            .push(json!({ "name": name, "offset": offset, "shape": shape }));
        json!(name)
    }

    fn dense(&mut self, name: &str, d: &Dense) -> Value {
        json!({
            "weight": self.add(&format!("{name}.weight"), &[d.d_in, d.d_out], &d.weight),
            "bias": self.add(&format!("{name}.bias"), &[d.d_out], &d.bias),
        })
    }

    /// A transport layer's weight as f16, `d_in + 16` rows of `pad16(d_out)` values.
    fn half_weight(&mut self, name: &str, d: &Dense) {
        let bits = half_weight_bits(&d.weight, d.d_in, d.d_out);
        let n_pad = pad16(d.d_out);
        self.half_tensors.push(json!({
            "name": name,
            "offset": self.halves.len(),
            "shape": [bits.len() / n_pad, n_pad],
            "weight_shape": [d.d_in, d.d_out],
        }));
        self.halves.extend(bits);
    }

    fn mlp(&mut self, name: &str, m: &Mlp) -> Value {
        let layers: Vec<Value> = (m.layers.iter().enumerate())
            .map(|(i, l)| {
                let name = format!("{name}.{i}");
                self.half_weight(&format!("{name}.weight"), l);
                self.dense(&name, l)
            })
            .collect();
        json!({ "hidden_activation": m.activation.to_string(), "layers": layers })
    }

    /// The light model, its tensors added: `encoder` (the paper's blocks and its dense layer
    /// into the code) or, for the linear design, `basis` (its functions' values at the texels
    /// and each texel's solid angle, which `light_project` multiplies the map by).
    fn light_model(&mut self, net: &NprtNet, input_width: usize) -> Value {
        match &net.light {
            LightModel::Encoder(e) => {
                let (convs, to_code) = self.encoder(e);
                json!({ "encoder": {
                    "input_width": input_width,
                    "blocks": convs,
                    "to_code": to_code,
                    // `encoder_block` runs this many threads per output value.
                    "block_threads_per_output": ENCODER_BLOCK_THREADS,
                }, "basis": null })
            }
            LightModel::Basis(b) => {
                let solid = b.texel_solid_angles();
                json!({ "encoder": null, "basis": {
                    "choice": b.choice.to_string(),
                    "input_width": b.width,
                    "size": b.size(),
                    "functions": self.add("basis.functions", &[b.size(), solid.len()], &b.functions),
                    "solid_angles": self.add("basis.solid_angles", &[solid.len()], &solid),
                }})
            }
        }
    }

    /// The encoder's blocks and its dense layer into the code, their tensors added.
    fn encoder(&mut self, encoder: &LightEncoder) -> (Vec<Value>, Value) {
        let convs: Vec<Value> = (encoder.convs.iter().enumerate())
            .map(|(i, c)| {
                json!({
                    "in_channels": c.c_in,
                    "out_channels": c.bias.len(),
                    "weight": self.add(&format!("encoder.conv{i}.weight"), &[c.bias.len(), c.c_in, 3, 3], &c.weight),
                    "bias": self.add(&format!("encoder.conv{i}.bias"), &[c.bias.len()], &c.bias),
                })
            })
            .collect();
        let to_code = self.dense("encoder.to_code", &encoder.to_code);
        (convs, to_code)
    }

    /// Each transport track: its kind, inputs, grid and networks, their tensors added.
    fn tracks(&mut self, net: &NprtNet) -> Vec<Value> {
        net.tracks.iter().enumerate()
            .map(|(i, t)| {
                let grid = t.grid.as_ref().map(|g| {
                    let g = &g.table;
                    let rows = g.len() / hash_grid::LEVEL_FEATURES;
                    json!({
                        "table": self.add(&format!("track{i}.grid"), &[rows, hash_grid::LEVEL_FEATURES], g),
                        "resolutions": hash_grid::resolutions(),
                    })
                });
                let transfer = t.transfer.as_ref().map(|m| self.mlp(&format!("track{i}.transfer"), m));
                // Its networks in the order they run, each by name, and how many of them run
                // before the light enters (what a still camera keeps): the track's plan.
                let plan = t.plan();
                let steps: Vec<Value> = (plan.steps.iter())
                    .map(|s| {
                        json!({
                            "network": s.net.name(),
                            "own_row": s.own_row,
                            "own_width": s.own_width,
                            "code_rows": s.code_rows.as_ref().map(|r| [r.start, r.end]),
                            "outputs": s.outputs,
                        })
                    })
                    .collect();
                json!({
                    "kind": t.kind.spec().name,
                    "kind_code": t.kind.code(),
                    "inputs": t.kind.inputs(),
                    "width": t.width(),
                    "grid": grid,
                    "transfer": transfer,
                    "shading": self.mlp(&format!("track{i}.shading"), &t.shading),
                    "steps": steps,
                    "kept": plan.kept,
                    // Which weight rows of the shading network's first layer multiply the light
                    // code: after ŝ, or first for the baseline's [ê, inputs]; none for a
                    // linear track, whose shading network reads ŝ alone.
                    "code_rows": t.light.code_rows().map(|rows| [rows.start, rows.end]),
                    // A linear track's K transfer coefficients per term and channel.
                    "coefficients": (t.light.after_networks()).then(|| t.light.coefficients()),
                })
            })
            .collect()
    }
}

/// Exports the model in `model_dir` into `out` (created if need be; files in it are replaced,
/// each atomically), with a worked example relighting `view` of its scene.
pub fn export_model(model_dir: &Path, out: &Path, view: &ExampleView) -> Result<ExportSummary> {
    let (file, net) = load_model(model_dir)?;
    if out.exists() && !out.is_dir() {
        bail!("--out '{}' is not a folder", out.display());
    }
    let mut files = Vec::new();
    let mut write = |name: &str, bytes: &[u8]| -> Result<()> {
        let path = out.join(name);
        nprt_io::write_file(&path, bytes)?;
        files.push(path);
        Ok(())
    };
    let mut kernels = Vec::new();
    let all = sources().into_iter().map(|k| (k, false));
    for (k, half) in all.chain(HALF_SOURCES.into_iter().map(|k| (k, true))) {
        kernels.push(
            export_kernel(k, half, &mut write).with_context(|| format!("kernel {}", k.name))?,
        );
    }

    let mut weights = WeightFile::default();
    let light = weights.light_model(&net, file.config.encoder_width);
    let tracks = weights.tracks(&net);
    write("weights.bin", &le_bytes(&weights.values, f32::to_le_bytes))?;
    write(
        "weights_f16.bin",
        &le_bytes(&weights.halves, u16::to_le_bytes),
    )?;
    let config = &file.config;
    let manifest = json!({
        "format": "nprt-export",
        "version": EXPORT_VERSION,
        "model": {
            "design": config.design.to_string(),
            "direct": config.direct.to_string(),
            "bounds": file.bounds,
            "output_gain": file.output_gain(),
            "map_norm": config.map_norm.to_string(),
            "scene": file.scene,
        },
        "encoder": light["encoder"],
        "basis": light["basis"],
        // Each pixel's network inputs (the G-buffer's 19 values, nprt-net's `FEATURES`) and
        // the light code's size.
        "inputs_per_pixel": FEATURES,
        "code_size": net.light.code_size(),
        // `gemm` computes a tile of this many rows and columns of its product per workgroup.
        "gemm_tile": GEMM_TILE,
        "tracks": tracks,
        "kernels": kernels,
        "weights": { "file": "weights.bin", "dtype": "f32le", "tensors": weights.tensors },
        "weights_f16": {
            "file": "weights_f16.bin",
            "dtype": "f16le",
            "layout": "each transport layer's weight (d_in × d_out, row-major) with every row padded by zeros to a multiple of 16 values, then 16 rows of zeros: what half_dense and half_dense_coop read; biases stay f32 in weights.bin",
            "tensors": weights.half_tensors,
        },
    });
    write(
        "export.json",
        serde_json::to_string_pretty(&manifest)?.as_bytes(),
    )?;
    let no_example = match example(model_dir, &file, view)? {
        Example::Files(example) => {
            for (name, bytes) in example {
                write(&name, &bytes)?;
            }
            for (name, text) in EXAMPLE_PAGE {
                write(name, text.as_bytes())?;
            }
            None
        }
        Example::Skipped(why) => Some(why),
    };
    Ok(ExportSummary {
        files,
        weights: weights.values.len(),
        no_example,
    })
}

/// `values` as the little-endian bytes `to_le` gives each: what the export's binary files hold.
fn le_bytes<T: Copy, const N: usize>(values: &[T], to_le: fn(T) -> [u8; N]) -> Vec<u8> {
    values.iter().flat_map(|&v| to_le(v)).collect()
}

/// The worked example's files (name in the export, contents), or why there is none.
enum Example {
    Files(Vec<(String, Vec<u8>)>),
    Skipped(String),
}

/// The worked example's data: a G-buffer of the model's scene (`gbuffer.bin`: per pixel the
/// 19 network inputs and the foreground mask), the encoder's input for a lighting
/// (`light.bin`), the CPU engine's radiance of the same (`reference.bin`), and
/// `example.json` saying what they are.
fn example(model_dir: &Path, file: &nprt_net::ModelFile, view: &ExampleView) -> Result<Example> {
    // The page shades its rows in one block (relight.js).
    if view.width as usize * view.height as usize > 65_536 {
        bail!(
            "the worked example's G-buffer is {}×{}: at most 65,536 pixels",
            view.width,
            view.height
        );
    }
    nprt_trace::Frame::check_size(view.width, view.height, "the worked example's G-buffer")?;
    if file.scene.is_empty() {
        return Ok(Example::Skipped(
            "the model does not record its scene".into(),
        ));
    }
    let scene = nprt_data::dataset::load_checked_scene(
        &file.scene,
        &file.scene_hash,
        &format!("model '{}' was trained on", model_dir.display()),
    )?;
    let Some(volume) = &scene.camera_volume else {
        return Ok(Example::Skipped(format!(
            "scene '{}' has no camera volume",
            file.scene
        )));
    };
    let camera = CameraPath::through_volume(volume).camera(0.0, view.width, view.height);
    let ts = TraceScene::new(&scene);
    let g = render_gbuffer(&ts, &camera);
    let map = nprt_scene::open_envmap(&view.map)?;
    let relighter = Relighter::load(model_dir, nprt_net::Engine::Cpu)?;
    let (reference, _) = relighter.shade(&g, (&map, 0.0))?;
    let config = &file.config;
    let input = config.light_input(&map, 0.0);
    let gain = file.output_gain();
    let scale: [f32; 3] = std::array::from_fn(|k| input.scale[k] * gain[k]);
    let gbuffer: Vec<f32> = (0..g.mask.len())
        .flat_map(|i| {
            let mut f = gbuffer_features(&file.bounds, &g, i).to_vec();
            f.push(g.mask[i]);
            f
        })
        .collect();
    let bytes = |v: &[f32]| le_bytes(v, f32::to_le_bytes);
    let description = json!({
        "width": view.width,
        "height": view.height,
        "map": view.map,
        "rotation_deg": 0.0,
        "gbuffer": { "file": "gbuffer.bin", "floats_per_pixel": FEATURES + 1, "layout": "19 network inputs, then the foreground mask, per pixel in row order" },
        // The map made into the light model's input: its texels divided by the divisor and,
        // for the encoder, through ln(1 + x); as they are for a basis.
        "light": { "file": "light.bin", "shape": [3, config.encoder_width / 2, config.encoder_width], "scale": scale, "log": config.texels() == nprt_net::Texels::Log },
        "reference": { "file": "reference.bin", "floats_per_pixel": 3, "engine": "nprt's CPU engine" },
        // A model that traces direct light leaves it to the renderer: its networks give the rest.
        "network_radiance": if config.direct.is_learned() { "all of it" } else { "indirect light only" },
    });
    let reference: Vec<f32> = reference.iter().flat_map(|c| c.to_array()).collect();
    Ok(Example::Files(vec![
        (
            "example/example.json".into(),
            serde_json::to_vec_pretty(&description)?,
        ),
        ("example/gbuffer.bin".into(), bytes(&gbuffer)),
        ("example/light.bin".into(), bytes(&input.pixels)),
        ("example/reference.bin".into(), bytes(&reference)),
    ]))
}

/// Writes kernel `k` (WGSL) and its translations, and says in export.json where they are. A
/// half-precision kernel (`half`) is translated where naga can (naga 30 writes no f16 GLSL,
/// nor cooperative matrices in HLSL); the manifest says why one is missing. An f32 kernel must
/// translate.
fn export_kernel(
    k: &KernelSource,
    half: bool,
    write: &mut impl FnMut(&str, &[u8]) -> Result<()>,
) -> Result<Value> {
    let caps = match half {
        true => {
            naga::valid::Capabilities::SHADER_FLOAT16
                | naga::valid::Capabilities::COOPERATIVE_MATRIX
        }
        false => naga::valid::Capabilities::empty(),
    };
    let [glsl, hlsl] = translate(k.wgsl, caps)?;
    write(&format!("{}.wgsl", k.name), k.wgsl.as_bytes())?;
    let (params, param_words, workgroup_size) = interface(k.wgsl)?;
    let mut entry = json!({
        "name": k.name,
        "precision": if half { "f16" } else { "f32" },
        "wgsl": format!("{}.wgsl", k.name),
        "entry_point": "main",
        "params": params,
        "param_words": param_words,
        "workgroup_size": workgroup_size,
    });
    for (language, file, text) in [
        ("glsl", format!("{}.comp.glsl", k.name), glsl),
        ("hlsl", format!("{}.hlsl", k.name), hlsl),
    ] {
        match text {
            Ok(text) => {
                write(&file, text.as_bytes())?;
                entry[language] = json!(file);
            }
            Err(why) if half => {
                entry[language] = Value::Null;
                entry[format!("{language}_missing")] =
                    json!(format!("naga cannot write it: {why}"));
            }
            Err(why) => bail!("naga cannot write its {language}: {why}"),
        }
    }
    Ok(entry)
}

/// What a caller of the kernel `wgsl` must know, read from its source: the fields of its
/// uniform parameters (binding 0: each a u32 word, by name and word index), their size in
/// words, and the entry point's workgroup size.
fn interface(wgsl: &str) -> Result<(Vec<Value>, u32, [u32; 3])> {
    let module = naga::front::wgsl::parse_str(wgsl)
        .map_err(|e| anyhow::anyhow!("{}", e.emit_to_string(wgsl)))?;
    let uniform = (module.global_variables.iter())
        .find(|(_, g)| {
            g.binding
                .as_ref()
                .is_some_and(|b| b.group == 0 && b.binding == 0)
        })
        .map(|(_, g)| &module.types[g.ty].inner)
        .context("no parameters at binding 0")?;
    let naga::TypeInner::Struct { members, span } = uniform else {
        bail!("its parameters at binding 0 are not a struct");
    };
    let params = (members.iter())
        .filter_map(|m| {
            m.name
                .as_ref()
                .map(|name| json!({ "name": name, "word": m.offset / 4 }))
        })
        .collect();
    let entry = module.entry_points.first().context("no entry point")?;
    Ok((params, span / 4, entry.workgroup_size))
}

/// `wgsl` validated with `caps`, then its GLSL (4.30 compute, bindings as in WGSL) and HLSL
/// translations, each or why naga could not write it.
pub fn translate(
    wgsl: &str,
    caps: naga::valid::Capabilities,
) -> Result<[std::result::Result<String, String>; 2]> {
    use naga::back::{glsl, hlsl};
    let module = naga::front::wgsl::parse_str(wgsl)
        .map_err(|e| anyhow::anyhow!("{}", e.emit_to_string(wgsl)))?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps)
        .validate(&module)
        .map_err(|e| anyhow::anyhow!("{}", e.emit_to_string(wgsl)))?;
    let mut glsl_text = String::new();
    // Explicit `layout(binding = N)`, N the WGSL binding, so that an engine binds the GLSL
    // kernels exactly as the WGSL ones (HLSL's registers follow the bindings already).
    let binding_map = module
        .global_variables
        .iter()
        .filter_map(|(_, g)| g.binding)
        .map(|b| (b, b.binding as u8))
        .collect();
    let options = glsl::Options {
        version: glsl::Version::Desktop(430),
        binding_map,
        ..Default::default()
    };
    let pipeline = glsl::PipelineOptions {
        shader_stage: naga::ShaderStage::Compute,
        entry_point: "main".into(),
        multiview: None,
    };
    let glsl = glsl::Writer::new(
        &mut glsl_text,
        &module,
        &info,
        &options,
        &pipeline,
        Default::default(),
    )
    .and_then(|mut w| w.write())
    .map(|_| glsl_text)
    .map_err(|e| format!("{e:?}"));
    let mut hlsl_text = String::new();
    let options = hlsl::Options::default();
    let pipeline = hlsl::PipelineOptions { entry_point: None };
    let hlsl = hlsl::Writer::new(&mut hlsl_text, &options, &pipeline)
        .write(&module, &info, None)
        .map(|_| hlsl_text)
        .map_err(|e| format!("{e:?}"));
    Ok([glsl, hlsl])
}
