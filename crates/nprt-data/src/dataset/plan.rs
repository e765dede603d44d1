//! Planning a dataset: the manifest as a pure function of the settings, so every shard computes
//! the same one.

use anyhow::{bail, Context, Result};
use nprt_scene::envmap::MAX_RADIANCE;
use nprt_scene::{CameraVolume, EnvMap, Scene};
use nprt_trace::{TraceDevice, TraceScene};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::manifest::{
    Jitter, Manifest, MapRecord, MixTerm, Settings, ViewRecord, VolumeRecord, FORMAT_VERSION,
};
use super::scene_identity::scene_hash;
use super::view_spec::ViewSpec;
use crate::cameras::place_camera;

/// The most maps `--mix-maps` mixes into a training view's lighting.
pub const MAX_MIX_MAPS: u32 = 8;

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
    pub views: ViewSpec,
}

/// How the views of a dataset take their maps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MapAssignment {
    /// This many maps are held out for testing; each view draws one of its split's maps,
    /// except the training views [`crate::lighting::takes_builtin`] picks with
    /// `builtin_share`: each of those has its own map, the maps after the pool's, in view order.
    Pool {
        test_maps: usize,
        builtin_share: f32,
    },
    /// The maps are one per view in view order (training views first), so no two views share
    /// a lighting and the test views' lightings are never trained on.
    PerView,
}

/// Builds the manifest: cameras, maps and rotations of every view, from the settings alone.
pub fn plan(req: &Request, ts: &TraceScene) -> Result<Manifest> {
    let builtin_share = match req.lighting {
        MapAssignment::Pool { builtin_share, .. } => builtin_share,
        MapAssignment::PerView => 0.0,
    };
    let own_map = |index: u64| crate::lighting::takes_builtin(req.views.seed, index, builtin_share);
    let mixed = crate::lighting::mixed_views(req.views.seed, req.views.train_views, builtin_share);
    let (train_pool, train_maps, test_maps) = map_split(req, mixed)?;
    check_jitter(&req.views.jitter)?;
    if !(1..=MAX_MIX_MAPS).contains(&req.views.mix_maps) {
        bail!(
            "mix_maps {}: a training view's lighting mixes 1 to {MAX_MIX_MAPS} maps",
            req.views.mix_maps
        );
    }
    let envmaps = map_records(req)?;
    let v = &req.volume;
    let settings = Settings {
        format_version: FORMAT_VERSION,
        scene: req.scene_spec.clone(),
        scene_hash: scene_hash(req.scene, &req.scene_source),
        envmaps,
        train_maps: train_maps.clone(),
        test_maps: test_maps.clone(),
        train_views: req.views.train_views,
        test_views: req.views.test_views,
        train_resolution: req.views.train_resolution,
        test_resolution: req.views.test_resolution,
        spp: req.views.spp,
        test_spp: Some(req.views.test_spp),
        max_depth: req.scene.max_depth,
        rr_depth: req.scene.rr_depth,
        seed: req.views.seed,
        jitter: req.views.jitter,
        mix_maps: req.views.mix_maps,
        camera_volume: VolumeRecord::from(v),
        transfer: None,
        tracer: TraceDevice::Cpu,
    };
    let views = plan_views(req, ts, &train_pool, &test_maps, mixed, own_map)?;
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

/// The maps the training views draw from, then each split's maps as recorded: the training
/// views' with the own maps of the `mixed` views, which follow the pool's; and the test views'.
fn map_split(req: &Request, mixed: usize) -> Result<(Vec<usize>, Vec<usize>, Vec<usize>)> {
    let views_total = (req.views.train_views + req.views.test_views) as usize;
    Ok(match req.lighting {
        MapAssignment::Pool { test_maps, .. } => {
            let Some(folder) = req.maps.len().checked_sub(mixed) else {
                bail!(
                    "{mixed} training views take a built-in lighting of their own, but only {} maps were given",
                    req.maps.len()
                );
            };
            let (train, test) = crate::lighting::split(folder, test_maps, req.views.seed)?;
            let recorded = train
                .iter()
                .copied()
                .chain(folder..req.maps.len())
                .collect();
            (train, recorded, test)
        }
        MapAssignment::PerView if req.maps.len() != views_total => bail!(
            "one map per view needs {views_total} maps, got {}",
            req.maps.len()
        ),
        MapAssignment::PerView => {
            let train: Vec<usize> = (0..req.views.train_views as usize).collect();
            (
                train.clone(),
                train,
                (req.views.train_views as usize..views_total).collect(),
            )
        }
    })
}

/// What the manifest records of each map: its spec, a hash of its file and its size.
fn map_records(req: &Request) -> Result<Vec<MapRecord>> {
    req.map_specs
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
        .collect()
}

/// Every view's camera, map, rotation, jitter and seed, in index order: training views draw
/// from `train_pool` (or, where `own_map` says, take the next of the mixed views' own maps,
/// which follow the pool's), test views from `test_maps`.
fn plan_views(
    req: &Request,
    ts: &TraceScene,
    train_pool: &[usize],
    test_maps: &[usize],
    mixed: usize,
    own_map: impl Fn(u64) -> bool,
) -> Result<Vec<ViewRecord>> {
    let mut views = Vec::with_capacity((req.views.train_views + req.views.test_views) as usize);
    let mut next_own = req.maps.len() - mixed;
    let brightest: Vec<glam::Vec3> = req
        .maps
        .iter()
        .map(|m| m.texels().iter().fold(glam::Vec3::ZERO, |a, t| a.max(*t)))
        .collect();
    for index in 0..req.views.train_views + req.views.test_views {
        let train = index < req.views.train_views;
        let (split, local, maps, [w, h]) = if train {
            ("train", index, train_pool, req.views.train_resolution)
        } else {
            (
                "test",
                index - req.views.train_views,
                test_maps,
                req.views.test_resolution,
            )
        };
        let mut rng = Pcg64Mcg::seed_from_u64(
            req.views
                .seed
                .wrapping_add(0x1f83_d9ab_fb41_bd6b)
                .wrapping_mul(index + 1),
        );
        let drawn = maps[(rng.random::<u64>() % maps.len() as u64) as usize];
        let map = match req.lighting {
            MapAssignment::PerView => index as usize,
            MapAssignment::Pool { .. } if train && own_map(index) => {
                next_own += 1;
                next_own - 1
            }
            MapAssignment::Pool { .. } => drawn,
        };
        let rotation_deg = rng.random::<f32>() * 360.0;
        let seed = rng.random::<u64>();
        let gain = if train {
            jittered_gain(&req.views.jitter, &mut rng)
        } else {
            [1.0; 3]
        };
        // Drawn after everything else, so that datasets without mixing plan as before.
        let mix = match train {
            true => mix_terms(req.views.mix_maps, train_pool, &mut rng),
            false => Vec::new(),
        };
        let lifted = (mix.iter()).fold(brightest[map] * glam::Vec3::from(gain), |sum, t| {
            sum + brightest[t.map] * t.gain
        });
        check_gain(lifted, &req.map_specs[map], gain, index)?;
        let camera = place_camera(ts, &req.volume, req.views.seed, index, w, h)?;
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
            mix,
        });
    }
    Ok(views)
}

/// A training view's mixed maps: up to `most` − 1 of the training maps `pool` (how many,
/// uniform from none), each turned at random about +Y and scaled by 2^−2u, u uniform in [0, 1].
fn mix_terms(most: u32, pool: &[usize], rng: &mut Pcg64Mcg) -> Vec<MixTerm> {
    if most <= 1 {
        return Vec::new();
    }
    let count = (rng.random::<u32>() % most) as usize;
    (0..count)
        .map(|_| MixTerm {
            map: pool[(rng.random::<u64>() % pool.len() as u64) as usize],
            rotation_deg: rng.random::<f32>() * 360.0,
            gain: (-2.0 * rng.random::<f32>()).exp2(),
        })
        .collect()
}

/// Refuses a view whose jitter would lift its map past [`MAX_RADIANCE`] when it is rendered,
/// before any view is: a dataset that stopped there could never be completed.
/// `lifted` is the brightest texel of the view's own map (`spec`) times its `gain`, plus those
/// of its mixed maps times theirs: a bound on its lighting's brightest texel.
fn check_gain(lifted: glam::Vec3, spec: &str, gain: [f32; 3], index: u64) -> Result<()> {
    if lifted.max_element() > MAX_RADIANCE {
        bail!(
            "view {index}: map '{spec}' times its exposure/tint jitter gain {gain:?} (with any \
             maps mixed in) reaches {lifted}, past the largest radiance a map may hold \
             ({MAX_RADIANCE:e}); scale the map down or lower --jitter-exposure/--jitter-tint"
        );
    }
    Ok(())
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

/// A request for a small dataset of the built-in room under two maps, one held out for the test
/// views (tests change what they need with struct update syntax).
#[cfg(test)]
pub(crate) fn room_request<'a>(scene: &'a Scene, map_specs: [&str; 2]) -> Request<'a> {
    let map_specs: Vec<String> = map_specs.map(String::from).into();
    Request {
        scene_spec: "builtin:room".into(),
        scene,
        scene_source: super::scene_source("builtin:room").unwrap(),
        volume: scene.camera_volume.clone().unwrap(),
        maps: crate::lighting::load_all(&map_specs).unwrap(),
        map_specs,
        lighting: MapAssignment::Pool {
            test_maps: 1,
            builtin_share: 0.0,
        },
        views: ViewSpec {
            train_views: 1,
            test_views: 1,
            train_resolution: [8, 8],
            test_resolution: [8, 8],
            spp: 2,
            test_spp: 2,
            seed: 0,
            jitter: Jitter::default(),
            mix_maps: 1,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lighting::{builtin_per_view, load_all, mixed_views, takes_builtin};
    use nprt_scene::{load_scene, SceneOptions};

    /// A map bright enough that the exposure jitter lifts it past the largest radiance a map
    /// may hold is refused when the dataset is planned, naming the view, map and gain, not
    /// when that view is rendered (a dataset that stops there can never be completed); the
    /// same map without jitter plans.
    #[test]
    fn jitter_that_would_lift_a_map_past_the_limit_is_refused_before_rendering() {
        let scene = load_scene("builtin:room", &SceneOptions::default()).unwrap();
        let ts = TraceScene::new(&scene);
        let bright = || EnvMap::constant(glam::Vec3::splat(0.9 * MAX_RADIANCE)).unwrap();
        let req = |jitter| {
            let base = room_request(&scene, ["builtin:indoor:1", "builtin:indoor:2"]);
            Request {
                maps: vec![bright(), bright()],
                views: ViewSpec {
                    train_views: 8,
                    jitter,
                    ..base.views
                },
                ..base
            }
        };
        assert!(plan(&req(Jitter::default()), &ts).is_ok());
        let err = plan(
            &req(Jitter {
                exposure: 1.0,
                tint: 0.0,
            }),
            &ts,
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.starts_with("view ")
                && err.contains("map 'builtin:indoor:")
                && err.contains("jitter gain")
                && err.contains("past the largest radiance a map may hold (1e12)"),
            "{err}"
        );
    }

    /// Mixing built-in lightings into a pool of maps gives the picked training views their own
    /// maps and leaves every other view, the test views among them, as without mixing.
    #[test]
    fn mixed_training_views_take_their_own_maps_and_leave_the_rest_alone() {
        let scene = load_scene("builtin:room", &SceneOptions::default()).unwrap();
        let ts = TraceScene::new(&scene);
        let (train_views, seed, share) = (40, 7, 0.5);
        let pool: Vec<String> = (1..=4).map(|i| format!("builtin:indoor:{i}")).collect();
        let mixed = mixed_views(seed, train_views, share);
        assert!((8..32).contains(&mixed), "{mixed} of {train_views} mixed");
        let manifest = |specs: Vec<String>, builtin_share| {
            let req = Request {
                scene_spec: "builtin:room".into(),
                scene: &scene,
                scene_source: vec![],
                volume: scene.camera_volume.clone().unwrap(),
                maps: load_all(&specs).unwrap(),
                map_specs: specs,
                lighting: MapAssignment::Pool {
                    test_maps: 1,
                    builtin_share,
                },
                views: ViewSpec {
                    train_views,
                    test_views: 6,
                    train_resolution: [4, 4],
                    test_resolution: [4, 4],
                    spp: 1,
                    test_spp: 2,
                    seed,
                    jitter: Jitter::default(),
                    mix_maps: 1,
                },
            };
            plan(&req, &ts)
        };
        let plain = manifest(pool.clone(), 0.0).unwrap();
        let own = builtin_per_view(mixed as u64, 0, seed);
        let with = manifest([pool.clone(), own].concat(), share).unwrap();
        let (p, w) = (&plain.settings, &with.settings);
        assert_eq!(p.test_maps, w.test_maps);
        assert_eq!(w.train_maps.len(), p.train_maps.len() + mixed);
        let mut next = pool.len();
        for (a, b) in plain.views.iter().zip(&with.views) {
            if a.split == "train" && takes_builtin(seed, a.index, share) {
                assert_eq!(b.map, next, "view {}", a.index);
                next += 1;
            } else {
                assert_eq!(a.map, b.map, "view {}", a.index);
                assert!(b.map < pool.len());
            }
            assert_eq!(
                (a.camera_to_world, a.rotation_deg, a.seed),
                (b.camera_to_world, b.rotation_deg, b.seed)
            );
        }
        assert_eq!(next, pool.len() + mixed);
        let err = manifest(pool, share).unwrap_err().to_string();
        assert!(err.contains("built-in lighting of their own"), "{err}");
    }

    /// `--mix-maps 3` gives training views 0 to 2 further training maps each, turned and
    /// scaled by 1/4 to 1, and leaves every other choice (cameras, own maps, rotations, seeds)
    /// and the test views as without it; the manifest records it, and refuses mixes it could
    /// not have planned.
    #[test]
    fn mixed_maps_join_training_views_only_and_change_nothing_else() {
        let scene = load_scene("builtin:room", &SceneOptions::default()).unwrap();
        let ts = TraceScene::new(&scene);
        let specs: Vec<String> = (1..=4).map(|i| format!("builtin:indoor:{i}")).collect();
        let req = |mix_maps| {
            let base = room_request(&scene, ["builtin:indoor:1", "builtin:indoor:2"]);
            Request {
                maps: load_all(&specs).unwrap(),
                map_specs: specs.clone(),
                views: ViewSpec {
                    train_views: 40,
                    mix_maps,
                    ..base.views
                },
                ..base
            }
        };
        let (one, three) = (plan(&req(1), &ts).unwrap(), plan(&req(3), &ts).unwrap());
        let counts: Vec<usize> = three.views.iter().map(|v| v.mix.len()).collect();
        for n in 0..3 {
            assert!(
                counts[..40].contains(&n),
                "no training view mixes {n} more: {counts:?}"
            );
        }
        assert!(counts[40..].iter().all(|&n| n == 0), "{counts:?}");
        for (a, b) in one.views.iter().zip(&three.views) {
            assert!(a.mix.is_empty());
            let b_plain = ViewRecord {
                mix: Vec::new(),
                ..b.clone()
            };
            assert_eq!(*a, b_plain);
            for t in &b.mix {
                assert!(three.settings.train_maps.contains(&t.map), "{t:?}");
                assert!((0.25..=1.0).contains(&t.gain), "{t:?}");
            }
        }
        let json = serde_json::to_string(&one).unwrap();
        assert!(!json.contains("mix"), "{json}");
        let json = serde_json::to_string(&three).unwrap();
        assert!(
            json.contains("\"mix_maps\":3") && json.contains("\"mix\":["),
            "{json}"
        );
        assert_eq!(serde_json::from_str::<Manifest>(&json).unwrap(), three);
        // A test view that mixes, or a view mixing more maps than planned, is refused.
        let mut bad = three.clone();
        let mixing = bad.views.iter().position(|v| !v.mix.is_empty()).unwrap();
        let term = bad.views[mixing].mix[0].clone();
        bad.views[40].mix.push(term.clone());
        assert!(format!("{:#}", bad.check().unwrap_err()).contains("only training views mix"));
        let mut bad = three.clone();
        bad.views[mixing].mix = vec![term; 3];
        assert!(format!("{:#}", bad.check().unwrap_err()).contains("at most 3"));
    }
}
