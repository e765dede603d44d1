//! Scenes and environment maps (files, `builtin:` names, numpy arrays) and a path-traced
//! reference frame of them.

use std::sync::{Arc, OnceLock};

use nprt_scene::SceneOptions;
use nprt_trace::{render, PixelFilter, RenderSettings, TraceScene};
use numpy::{AllowTypeChange, PyArray2, PyArray3, PyArrayLike2, PyArrayLike3};
use pyo3::prelude::*;

use crate::argument;
use crate::arrays::{self, CameraOut};
use crate::error::{input_error, OrPy};
use crate::interruptible::interruptible;

/// A scene: geometry, materials and, where its file has one, a camera.
#[pyclass(frozen, module = "nprt")]
pub struct Scene {
    pub spec: String,
    pub scene: Arc<nprt_scene::Scene>,
    /// The scene made ready for tracing (its acceleration structure), at the first frame
    /// rendered and kept for the next.
    traced: OnceLock<TraceScene<'static>>,
    /// Its identity as datasets and models record it, made at the first check.
    hash: OnceLock<Option<String>>,
}

impl Scene {
    /// The scene ready for tracing, made once.
    pub fn traced(&self) -> &TraceScene<'static> {
        self.traced
            .get_or_init(|| TraceScene::shared(self.scene.clone()))
    }

    /// Its hash as a dataset or a model records its scene's (None where its file can no
    /// longer be read).
    pub fn hash(&self) -> Option<&str> {
        self.hash
            .get_or_init(|| {
                let source = nprt_data::dataset::scene_source(&self.spec).ok()?;
                Some(nprt_data::dataset::scene_hash(&self.scene, &source))
            })
            .as_deref()
    }
}

#[pymethods]
impl Scene {
    /// What it was loaded from: a file or a `builtin:` name.
    #[getter]
    fn spec(&self) -> &str {
        &self.spec
    }

    /// The scene's bounding box, ((x, y, z) min, (x, y, z) max), as tuples.
    #[getter]
    fn bounds(&self) -> ((f32, f32, f32), (f32, f32, f32)) {
        let (lo, hi) = self.scene.bounds();
        (lo.into(), hi.into())
    }

    /// Triangles in all meshes.
    #[getter]
    fn triangles(&self) -> usize {
        self.scene.meshes.iter().map(|m| m.indices.len()).sum()
    }

    /// Warnings the loader gave (what it changed or left out, and why).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.scene.warnings.clone()
    }

    /// The scene's own camera, or one framing its bounds: (4 × 4 camera-to-world matrix,
    /// horizontal field of view in degrees, (width, height)).
    fn camera<'py>(&self, py: Python<'py>) -> CameraOut<'py> {
        let c = (self.scene.camera.clone()).unwrap_or_else(|| self.scene.framing_camera());
        let fov = (2.0 * c.tan_half_x().atan()).to_degrees();
        (arrays::matrix(py, c.to_world), fov, (c.width, c.height))
    }

    /// The environment map the scene's file names, if any (nprt lights scenes by such maps
    /// only).
    #[getter]
    fn envmap(&self) -> Option<EnvMap> {
        self.scene.envmap.clone().map(|map| EnvMap { map })
    }

    fn __repr__(&self) -> String {
        format!(
            "nprt.Scene('{}', {} triangles)",
            self.spec,
            self.triangles()
        )
    }
}

/// Loads a scene: `builtin:room`, or a Mitsuba .xml, glTF (.gltf/.glb), .ply or .obj file
/// (a `str` or a `pathlib.Path`).
#[pyfunction]
pub fn load_scene(py: Python<'_>, spec: &Bound<'_, PyAny>) -> PyResult<Scene> {
    load(
        py,
        &argument::text(spec, "spec", "a str or an os.PathLike")?,
    )
}

/// The scene `spec` names, loaded with the GIL released.
pub fn load(py: Python<'_>, spec: &str) -> PyResult<Scene> {
    let scene = py
        .detach(|| nprt_scene::load_scene(spec, &SceneOptions::default()))
        .or_py()?;
    Ok(Scene {
        spec: spec.to_string(),
        scene: Arc::new(scene),
        traced: OnceLock::new(),
        hash: OnceLock::new(),
    })
}

/// A lat-long environment map (Mitsuba 3's mapping), 2:1, linear RGB radiance.
#[pyclass(frozen, module = "nprt")]
pub struct EnvMap {
    pub map: nprt_scene::EnvMap,
}

#[pymethods]
impl EnvMap {
    /// A map from an (H, 2H, 3) array of linear radiance (negative values are clamped to 0).
    #[new]
    #[pyo3(signature = (texels, name = "array"))]
    fn new(texels: &Bound<'_, PyAny>, name: &str) -> PyResult<Self> {
        let kind = texels.get_type().name()?;
        // A view stays a view (a broadcast array is not copied); nested lists become an array.
        let array = (texels.py().import("numpy")?)
            .call_method1("asarray", (texels,))
            .map_err(|e| input_error(format!("texels: not an array of numbers ({e})")))?;
        let shape = || -> PyResult<Vec<usize>> { array.getattr("shape")?.extract() };
        let Ok(&[h, w, c]) = shape().as_deref() else {
            return Err(input_error(format!(
                "texels: an environment map is an (H, 2H, 3) array of numbers, not {kind}{}",
                shape().map_or(String::new(), |s| format!(" of shape {s:?}"))
            )));
        };
        if c != 3 {
            return Err(input_error(format!(
                "texels: an environment map is an (H, 2H, 3) array, got shape ({h}, {w}, {c})"
            )));
        }
        // Before any copy: a broadcast view of a huge shape costs nothing until copied.
        nprt_scene::EnvMap::check_size(w, h, name).or_py()?;
        let texels: PyArrayLike3<f32, AllowTypeChange> = (array.extract())
            .map_err(|e| input_error(format!("texels: not an array of numbers ({e})")))?;
        let texels = texels
            .as_array()
            .iter()
            .copied()
            .collect::<Vec<f32>>()
            .chunks_exact(3)
            .map(glam::Vec3::from_slice)
            .collect();
        let map = nprt_scene::EnvMap::from_texels(name, w, h, texels).or_py()?;
        Ok(EnvMap { map })
    }

    /// Its texels as an (H, 2H, 3) float32 array.
    fn to_array<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f32>> {
        arrays::image(py, self.map.texels(), self.map.width(), self.map.height())
    }

    /// The same map turned by `degrees` about +Y (Mitsuba's `<rotate y="1" angle=.../>`).
    fn rotated(&self, degrees: f32) -> PyResult<EnvMap> {
        Ok(EnvMap {
            map: self.map.rotated_y(argument::finite(degrees, "degrees")?),
        })
    }

    #[getter]
    fn name(&self) -> &str {
        self.map.name()
    }

    /// (height, width) in texels.
    #[getter]
    fn shape(&self) -> (usize, usize) {
        (self.map.height(), self.map.width())
    }

    fn __repr__(&self) -> String {
        format!(
            "nprt.EnvMap('{}', {}×{})",
            self.map.name(),
            self.map.width(),
            self.map.height()
        )
    }
}

/// The 4 × 4 camera-to-world matrix of a camera at `origin` looking at `target` with `up`
/// upwards (Mitsuba's `lookat`: columns left, up, forward, origin).
#[pyfunction]
#[pyo3(signature = (origin, target, up = [0.0, 1.0, 0.0]), text_signature = "(origin, target, up=(0.0, 1.0, 0.0))")]
pub fn look_at<'py>(
    py: Python<'py>,
    origin: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    for (arg, v) in [("origin", origin), ("target", target), ("up", up)] {
        if !v.iter().all(|c| c.is_finite()) {
            return Err(input_error(format!(
                "{arg} must be three finite numbers, got {v:?}"
            )));
        }
    }
    let (o, t, u): (glam::Vec3, glam::Vec3, glam::Vec3) = (origin.into(), target.into(), up.into());
    if o == t {
        return Err(input_error(
            "a camera cannot look at its own origin (origin == target)",
        ));
    }
    if (t - o).cross(u).length_squared() == 0.0 {
        return Err(input_error(
            "up must not be parallel to the viewing direction (target - origin)",
        ));
    }
    Ok(arrays::matrix(
        py,
        nprt_scene::Camera::look_at(o, t, u, 60.0, 1, 1).to_world,
    ))
}

/// Opens an environment map: an .exr/.hdr file (a `str` or a `pathlib.Path`),
/// `builtin:sky[:ELEV[:AZIM[:TURB]]]` or `builtin:indoor[:SEED]`.
#[pyfunction]
pub fn open_envmap(py: Python<'_>, spec: &Bound<'_, PyAny>) -> PyResult<EnvMap> {
    open(
        py,
        &argument::text(spec, "spec", "a str or an os.PathLike")?,
    )
}

/// The map `spec` names, opened with the GIL released.
pub fn open(py: Python<'_>, spec: &str) -> PyResult<EnvMap> {
    let map = py.detach(|| nprt_scene::open_envmap(spec)).or_py()?;
    Ok(EnvMap { map })
}

/// A path-traced frame of `scene` under `envmap` through `camera` (4 × 4 camera-to-world,
/// horizontal field of view `fov`), `spp` paths per pixel over the pixel (box filter), as
/// `nprt reference` renders: an (H, W, 3) float32 array of linear radiance. `scene` and
/// `envmap` may be loaded objects or what names them (a `str` or a `pathlib.Path`). Ctrl-C
/// stops it within a moment (`nprt.Interrupted`).
#[pyfunction]
#[pyo3(signature = (scene, envmap, camera, width, height, fov = 60.0, spp = 64, seed = 0, max_depth = None))]
#[allow(clippy::too_many_arguments)]
pub fn reference<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    envmap: &Bound<'py, PyAny>,
    camera: PyArrayLike2<f32, AllowTypeChange>,
    width: i64,
    height: i64,
    fov: f32,
    spp: u32,
    seed: u64,
    max_depth: Option<u32>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let (width, height) = arrays::frame_size(width, height)?;
    let camera = arrays::camera(camera, fov, width, height).or_py()?;
    if spp == 0 {
        return Err(input_error("spp (samples per pixel) must be at least 1"));
    }
    let scene = scene_arg(scene, "scene")?;
    let envmap = envmap_arg(envmap, "envmap")?;
    let scene = scene.get();
    let settings = RenderSettings {
        spp,
        max_depth: max_depth.or(scene.scene.max_depth),
        rr_depth: scene.scene.rr_depth,
        seed,
        filter: PixelFilter::Box,
        progress: false,
    };
    let map = &envmap.get().map;
    let frame = interruptible(py, || Ok(render(scene.traced(), &camera, map, &settings)))?;
    Ok(arrays::image(
        py,
        &frame.radiance,
        width as usize,
        height as usize,
    ))
}

const SCENE: &str = "an nprt.Scene, a str or an os.PathLike (a scene file or builtin:room)";
const MAP: &str = "an nprt.EnvMap, a str or an os.PathLike (an .exr/.hdr file or a builtin: map)";

/// The scene `obj` is or names (`builtin:room`, a file), loaded where it is named.
pub fn scene_arg<'py>(obj: &Bound<'py, PyAny>, arg: &str) -> PyResult<Bound<'py, Scene>> {
    if let Ok(s) = obj.cast::<Scene>() {
        return Ok(s.clone());
    }
    let spec = argument::text(obj, arg, SCENE)?;
    Bound::new(obj.py(), load(obj.py(), &spec)?)
}

/// What `obj` names as a scene, to hand a command: a loaded scene's own spec.
pub fn scene_spec(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<String> {
    match obj.cast::<Scene>() {
        Ok(s) => Ok(s.get().spec.clone()),
        Err(_) => argument::text(obj, arg, SCENE),
    }
}

/// The lightings of a dataset `obj` names: a folder of maps (a str or an os.PathLike), or
/// "builtin" (`generate`'s, `paper`'s and `bake`'s `envmaps`).
pub fn envmaps_spec(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    argument::text(
        obj,
        "envmaps",
        "a folder of maps (a str or an os.PathLike) or \"builtin\"",
    )
}

/// The map `obj` is or names, opened where it is named.
pub fn envmap_arg<'py>(obj: &Bound<'py, PyAny>, arg: &str) -> PyResult<Bound<'py, EnvMap>> {
    if let Ok(m) = obj.cast::<EnvMap>() {
        return Ok(m.clone());
    }
    let spec = argument::text(obj, arg, MAP)?;
    Bound::new(obj.py(), open(obj.py(), &spec)?)
}
