//! `nprt reference`: flags for a reference render; the work is `nprt_trace::render_reference`.

use std::path::PathBuf;

use anyhow::Result;
use nprt_trace::{render_reference, ReferenceOptions};

use crate::flags::{parse_set, print_warnings};

#[derive(clap::Args)]
pub struct ReferenceArgs {
    /// Scene: a Mitsuba 3 .xml, a glTF .gltf/.glb, a .ply/.obj mesh, or builtin:room.
    scene: String,
    /// Output OpenEXR file (radiance as R,G,B plus direct.*, position.*, normal.*, view.*,
    /// kd.*, ks.*, alpha, mask).
    #[arg(long)]
    out: PathBuf,
    /// Samples per pixel (default: the scene's sampler, else 64).
    #[arg(long)]
    spp: Option<u32>,
    /// Set a Mitsuba `<default>` parameter, e.g. --set envmap=maps/park.exr (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// Light with this map instead of the scene's (whose own map file is then not read): an
    /// .exr/.hdr file, builtin:sky[:ELEV[:AZIM[:TURB]]] or builtin:indoor[:SEED]. Required
    /// for scenes without one.
    #[arg(long)]
    envmap: Option<String>,
    /// Rotate the environment about +Y by this many degrees.
    #[arg(long, value_parser = crate::flags::finite_f32, default_value_t = 0.0)]
    rotate: f32,
    /// Override the integrator's max_depth (Mitsuba's meaning; -1 is unlimited).
    #[arg(long, allow_negative_numbers = true)]
    max_depth: Option<i64>,
    /// Override the film width (with --height).
    #[arg(long, requires = "height")]
    width: Option<u32>,
    /// Override the film height (with --width).
    #[arg(long, requires = "width")]
    height: Option<u32>,
    /// Random seed; the same seed gives the same image on any number of threads.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Also write a tone-mapped (clamped sRGB) PNG preview here.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Trace every sample through the pixel centre (the dataset convention) instead of
    /// box-filtering over the pixel.
    #[arg(long)]
    centre: bool,
}

pub fn run(a: ReferenceArgs) -> Result<()> {
    let opts = ReferenceOptions {
        set: parse_set(&a.set)?,
        envmap: a.envmap,
        rotate_deg: a.rotate,
        max_depth: a.max_depth,
        resolution: a.width.zip(a.height).map(|(w, h)| [w, h]),
        spp: a.spp,
        seed: a.seed,
        centre: a.centre,
        progress: true,
    };
    nprt_io::check_writable(&a.out)?;
    let r = render_reference(&a.scene, &opts)?;
    print_warnings(&r.warnings);
    let f = &r.frame;
    f.write_exr(&a.out)?;
    if let Some(png) = &a.png {
        nprt_io::write_png(&f.radiance, f.width, f.height, 0.0, png)?;
    }
    let m = f.mean();
    println!(
        "rendered {}×{} at {} spp (max_depth {}) in {:.3} s ({:.3} Msamples/s; scene load {:.3} s + BVH {:.3} s), {} triangles",
        r.camera.width,
        r.camera.height,
        r.settings.spp,
        r.settings
            .max_depth
            .map_or("unlimited".into(), |d| d.to_string()),
        r.render_s,
        r.samples_per_s() / 1e6,
        r.load_s,
        r.bvh_s,
        r.triangles,
    );
    println!(
        "mean radiance {:.5} {:.5} {:.5}; wrote {}",
        m.x,
        m.y,
        m.z,
        a.out.display()
    );
    Ok(())
}
