//! Planning a dataset: the manifest as a pure function of the settings, so every shard computes
//! the same one.

use anyhow::{bail, Context, Result};
use nprt_scene::{CameraVolume, EnvMap, Scene};
use nprt_trace::TraceScene;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::manifest::{
    Jitter, Manifest, MapRecord, Settings, ViewRecord, VolumeRecord, FORMAT_VERSION,
};
use super::scene_identity::scene_hash;
use crate::cameras::place_camera;

/// What a run of `generate` is asked to do.
pub struct Request<'a> {
    pub scene_spec: String,
    pub scene: &'a Scene,
    pub scene_source: Vec<u8>,
    pub volume: CameraVolume,
    pub map_specs: Vec<String>,
    pub maps: Vec<EnvMap>,
    /// How views take their maps: from a pool split into training and held-out maps, or one
    /// map per view.
    pub lighting: MapAssignment,
    pub train_views: u64,
    pub test_views: u64,
    pub train_resolution: [u32; 2],
    pub test_resolution: [u32; 2],
    pub spp: u32,
    /// Samples per pixel of the test views: even, at least 2.
    pub test_spp: u32,
    pub seed: u64,
    /// Exposure and white-balance changes of the training views' maps.
    pub jitter: Jitter,
}

/// How the views of a dataset take their maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapAssignment {
    /// This many maps are held out for testing; each view draws one of its split's maps.
    Pool { test_maps: usize },
    /// The maps are one per view in view order (training views first), so no two views share
    /// a lighting and the test views' lightings are never trained on.
    PerView,
}

/// Builds the manifest: cameras, maps and rotations of every view, from the settings alone.
pub fn plan(req: &Request, ts: &TraceScene) -> Result<Manifest> {
    let views_total = (req.train_views + req.test_views) as usize;
    let (train_maps, test_maps) = match req.lighting {
        MapAssignment::Pool { test_maps } => {
            crate::lighting::split(req.maps.len(), test_maps, req.seed)?
        }
        MapAssignment::PerView if req.maps.len() != views_total => bail!(
            "one map per view needs {views_total} maps, got {}",
            req.maps.len()
        ),
        MapAssignment::PerView => {
            let train = req.train_views as usize;
            ((0..train).collect(), (train..views_total).collect())
        }
    };
    check_jitter(&req.jitter)?;
    let envmaps = req
        .map_specs
        .iter()
        .zip(&req.maps)
        .map(|(spec, map)| {
            let hash = crate::lighting::map_hash(spec)?;
            Ok(MapRecord {
                spec: spec.clone(),
                hash,
                width: map.width(),
                height: map.height(),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let v = &req.volume;
    let settings = Settings {
        format_version: FORMAT_VERSION,
        scene: req.scene_spec.clone(),
        scene_hash: scene_hash(req.scene, &req.scene_source),
        envmaps,
        train_maps: train_maps.clone(),
        test_maps: test_maps.clone(),
        train_views: req.train_views,
        test_views: req.test_views,
        train_resolution: req.train_resolution,
        test_resolution: req.test_resolution,
        spp: req.spp,
        test_spp: Some(req.test_spp),
        max_depth: req.scene.max_depth,
        rr_depth: req.scene.rr_depth,
        seed: req.seed,
        jitter: req.jitter,
        camera_volume: VolumeRecord {
            min: v.min.into(),
            max: v.max.into(),
            look: v.look.into(),
            spread_deg: v.spread_deg,
            fov_deg: v.fov_deg,
        },
    };
    let mut views = Vec::with_capacity((req.train_views + req.test_views) as usize);
    for index in 0..req.train_views + req.test_views {
        let train = index < req.train_views;
        let (split, local, pool, [w, h]) = if train {
            ("train", index, &train_maps, req.train_resolution)
        } else {
            (
                "test",
                index - req.train_views,
                &test_maps,
                req.test_resolution,
            )
        };
        let mut rng = Pcg64Mcg::seed_from_u64(
            req.seed
                .wrapping_add(0x1f83_d9ab_fb41_bd6b)
                .wrapping_mul(index + 1),
        );
        let drawn = pool[(rng.random::<u64>() % pool.len() as u64) as usize];
        let map = match req.lighting {
            MapAssignment::Pool { .. } => drawn,
            MapAssignment::PerView => index as usize,
        };
        let rotation_deg = rng.random::<f32>() * 360.0;
        let seed = rng.random::<u64>();
        let gain = if train {
            jittered_gain(&req.jitter, &mut rng)
        } else {
            [1.0; 3]
        };
        let camera = place_camera(ts, &req.volume, req.seed, index, w, h)?;
        views.push(ViewRecord {
            index,
            split: split.into(),
            file: format!("views/{split}_{local:05}.exr"),
            camera_to_world: camera.to_world.to_cols_array(),
            fov_x_deg: camera.fov_deg,
            width: w,
            height: h,
            map,
            rotation_deg,
            gain,
            seed,
        });
    }
    let (lo, hi) = req.scene.bounds();
    let manifest = Manifest {
        settings,
        bounds: [lo.into(), hi.into()],
        views,
    };
    manifest
        .check()
        .with_context(|| format!("cannot plan a dataset for scene '{}'", req.scene_spec))?;
    Ok(manifest)
}

/// Refuses jitter that could not be recorded (gains are kept within [1/64, 64]).
fn check_jitter(j: &Jitter) -> Result<()> {
    for (name, stops) in [("exposure", j.exposure), ("tint", j.tint)] {
        if !(0.0..=2.0).contains(&stops) {
            bail!("{name} jitter must be between 0 and 2 stops, got {stops}");
        }
    }
    Ok(())
}

/// A training view's map gain: 2^e · (2^r, 1, 2^b) at unit luminance (see [`Jitter`]).
fn jittered_gain(j: &Jitter, rng: &mut Pcg64Mcg) -> [f32; 3] {
    if j.is_none() {
        return [1.0; 3];
    }
    let mut stops = |range: f32| (rng.random::<f32>() * 2.0 - 1.0) * range;
    let (e, r, b) = (stops(j.exposure), stops(j.tint), stops(j.tint));
    let tint = glam::Vec3::new(r.exp2(), 1.0, b.exp2());
    (tint / nprt_scene::luminance(tint) * e.exp2()).to_array()
}
