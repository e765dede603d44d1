//! Scenes and environment maps (files, `builtin:` names, numpy arrays) and a path-traced
//! reference frame of them.

use std::sync::{Arc, OnceLock};

use nprt_scene::SceneOptions;
use nprt_trace::{render, PixelFilter, RenderSettings, TraceScene};
use numpy::{PyArray2, PyArray3};
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

    /// Pickled by what it was loaded from (a worker process loads it again).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Reduced<'py, (String,)>> {
        Ok((
            py.import("nprt")?.getattr("load_scene")?,
            (self.spec.clone(),),
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "nprt.Scene('{}', {} triangles)",
            self.spec,
            self.triangles()
        )
    }
}

/// Loads the scene `spec` names: `builtin:room`, or a Mitsuba .xml, glTF (.gltf/.glb), .ply or
/// .obj file (a `str` or a `pathlib.Path`).
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

/// What `__reduce__` gives pickle: a callable and its arguments.
pub type Reduced<'py, A> = (Bound<'py, PyAny>, A);

/// A lat-long environment map (Mitsuba 3's mapping), 2:1, linear RGB radiance: made from
/// `texels`, an (H, 2H, 3) array of real numbers, called `name` (negative texels are clamped to
/// 0, and a map black everywhere, with a `UserWarning`), or opened with `nprt.open_envmap`.
#[pyclass(frozen, module = "nprt")]
pub struct EnvMap {
    pub map: nprt_scene::EnvMap,
}

#[pymethods]
impl EnvMap {
    /// A map from `texels`, an (H, 2H, 3) array of linear radiance (real numbers; negative
    /// values are clamped to 0 with a warning, as is a map black everywhere), called `name`.
    #[new]
    #[pyo3(signature = (texels, name = None), text_signature = "(texels, name='array')")]
    fn new(texels: &Bound<'_, PyAny>, name: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let py = texels.py();
        let name = argument::text_or_none(name, "name", "a str")?.unwrap_or("array".into());
        let (array, h, w) = argument::rgb_array(texels, "texels", "an (H, 2H, 3) array")?;
        // Before any copy: a broadcast view of a huge shape costs nothing until copied.
        nprt_scene::EnvMap::check_size(w, h, &name)
            .map_err(|e| argument::refused(texels, "texels", format!("{e:#}")))?;
        let texels_rgb = argument::rgb_texels(&array, "texels")?;
        let map = nprt_scene::EnvMap::from_texels(&name, w, h, texels_rgb)
            .map_err(|e| argument::refused(texels, "texels", format!("{e:#}")))?;
        let warn = |message: String| {
            PyErr::warn(
                py,
                &py.get_type::<pyo3::exceptions::PyUserWarning>(),
                &std::ffi::CString::new(message)?,
                1,
            )
        };
        // What the map changed (negative texels clamped) or says (black everywhere).
        for w in map.warnings() {
            warn(w)?;
        }
        Ok(EnvMap { map })
    }

    /// Its texels as an (H, 2H, 3) float32 array.
    fn to_array<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f32>> {
        arrays::image(py, self.map.texels(), self.map.width(), self.map.height())
    }

    /// `numpy.asarray(map)`: its texels (as `to_array`), in `dtype` where one is asked.
    #[pyo3(signature = (dtype = None, copy = None))]
    fn __array__<'py>(
        &self,
        py: Python<'py>,
        dtype: Option<&Bound<'py, PyAny>>,
        copy: Option<bool>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let _ = copy; // a new array every call: a copy either way
        let texels = self.to_array(py).into_any();
        match dtype.filter(|d| !d.is_none()) {
            Some(d) => texels.call_method1("astype", (d,)),
            None => Ok(texels),
        }
    }

    /// Pickled by its texels and name.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Reduced<'py, (Bound<'py, PyArray3<f32>>, String)>> {
        let class = py.import("nprt")?.getattr("EnvMap")?;
        Ok((class, (self.to_array(py), self.map.name().to_string())))
    }

    /// The same map turned by `degrees` about +Y (Mitsuba's `<rotate y="1" angle=.../>`).
    fn rotated(&self, degrees: &Bound<'_, PyAny>) -> PyResult<EnvMap> {
        let degrees = argument::number(degrees, "degrees", argument::FINITE)? as f32;
        Ok(EnvMap {
            map: self.map.rotated_y(degrees),
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
#[pyo3(signature = (origin, target, up = None), text_signature = "(origin, target, up=(0.0, 1.0, 0.0))")]
pub fn look_at<'py>(
    py: Python<'py>,
    origin: &Bound<'py, PyAny>,
    target: &Bound<'py, PyAny>,
    up: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let origin = argument::vec3(origin, "origin")?;
    let target = argument::vec3(target, "target")?;
    let up = argument::vec3_or_none(up, "up")?.unwrap_or([0.0, 1.0, 0.0]);
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

/// Opens the environment map `spec` names: an .exr/.hdr file (a `str` or a `pathlib.Path`),
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
/// horizontal field of view `fov`) at `width` × `height` pixels, `spp` paths per pixel over the
/// pixel (box filter) from `seed`, each at most `max_depth` bounces (None: the scene's), as
/// `nprt reference` renders: an (H, W, 3) float32 array of linear radiance. `scene` and
/// `envmap` may be loaded objects or what names them (a `str` or a `pathlib.Path`). Ctrl-C
/// stops it within a moment (`nprt.Interrupted`).
#[pyfunction]
#[pyo3(
    signature = (scene, envmap, camera, width, height, fov = None, spp = None, seed = None, max_depth = None),
    text_signature = "(scene, envmap, camera, width, height, fov=60.0, spp=64, seed=0, max_depth=None)"
)]
#[allow(clippy::too_many_arguments)]
pub fn reference<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    envmap: &Bound<'py, PyAny>,
    camera: &Bound<'py, PyAny>,
    width: &Bound<'py, PyAny>,
    height: &Bound<'py, PyAny>,
    fov: Option<&Bound<'py, PyAny>>,
    spp: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    max_depth: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let (width, height) = arrays::frame_size(width, height)?;
    let camera = arrays::camera(camera, fov, width, height)?;
    let spp = argument::whole_or_none(spp, "spp", 1..=u32::MAX)?.unwrap_or(64);
    let seed = argument::whole_or_none(seed, "seed", 0..=u64::MAX)?.unwrap_or(0);
    let max_depth = argument::whole_or_none(max_depth, "max_depth", 0..=u32::MAX)?;
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
