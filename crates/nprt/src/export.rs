//! `nprt export`: flags for writing a trained model as shaders and weights for engines; the
//! work is `nprt_render::gpu::export_model`.

use std::path::PathBuf;

use anyhow::Result;

use nprt_render::ExampleView;

use crate::flags::Resolution;

/// The worked example's defaults, from the one place that states them.
fn example() -> ExampleView {
    ExampleView::default()
}

#[derive(clap::Args)]
pub struct ExportArgs {
    /// Trained model folder (from `nprt train`).
    model: PathBuf,
    /// Output folder: the kernels as WGSL, GLSL 4.30 and HLSL 5.1, weights.bin (every weight,
    /// f32 little-endian) and export.json (where each tensor lies, how the networks are wired,
    /// the order of dispatches); documented in docs/export.md.
    #[arg(long)]
    out: PathBuf,
    /// Size of the worked example's G-buffer (example/: a WebGPU page relighting a view of the
    /// model's scene, from the start of `nprt render`'s default camera path), N or WxH.
    #[arg(long, default_value_t = Resolution([example().width, example().height]))]
    example_res: Resolution,
    /// The worked example's lighting: an .exr/.hdr map or a built-in spec.
    #[arg(long, default_value_t = example().map)]
    example_map: String,
}

#[cfg(feature = "gpu")]
pub fn run(a: ExportArgs) -> Result<()> {
    let [width, height] = a.example_res.0;
    let view = ExampleView {
        width,
        height,
        map: a.example_map,
    };
    let done = nprt_render::gpu::export_model(&a.model, &a.out, &view)?;
    let file = nprt_net::read_model_file(&a.model)?;
    println!(
        "nprt export: {} ({}) → {}: {} files, {} weights ({:.2} MB)",
        a.model.display(),
        file.describe("left to the engine's renderer, docs/export.md"),
        a.out.display(),
        done.files.len(),
        done.weights,
        done.weights as f64 * 4e-6
    );
    match done.no_example {
        None => println!(
            "worked example: serve {} over HTTP from localhost and open /example/ in a browser with WebGPU",
            a.out.display()
        ),
        Some(why) => println!("no worked example: {why}"),
    }
    Ok(())
}

#[cfg(not(feature = "gpu"))]
pub fn run(_: ExportArgs) -> Result<()> {
    anyhow::bail!(
        "nprt export: this nprt was built without the GPU frame path; rebuild it with \
         `cargo build --release --features gpu` (docs/building.md)"
    )
}
