//! Scenes and environment maps (files, `builtin:` names, numpy arrays) and a path-traced
//! reference frame of them.

use std::sync::{Arc, OnceLock};

use nprt_scene::SceneOptions;
use nprt_trace::{render, PixelFilter, RenderSettings, TraceScene};
use numpy::{AllowTypeChange, PyArray2, PyArray3, PyArrayLike2, PyArrayLike3};
use pyo3::prelude::*;

use crate::arrays::{self, CameraOut};
use crate::error::OrPy;

/// A scene: geometry, materials and, where its file has one, a camera.
#[pyclass(frozen, module = "nprt")]
pub struct Scene {
    pub spec: String,
    pub scene: Arc<nprt_scene::Scene>,
    /// The scene made ready for tracing (its acceleration structure), at the first frame
    /// rendered and kept for the next.
    traced: OnceLock<TraceScene<'static>>,
}

impl Scene {
    /// The scene ready for tracing, made once.
    pub fn traced(&self) -> &TraceScene<'static> {
        self.traced
            .get_or_init(|| TraceScene::shared(self.scene.clone()))
    }
}

#[pymethods]
impl Scene {
    /// What it was loaded from: a file or a `builtin:` name.
    #[getter]
    fn spec(&self) -> &str {
        &self.spec
    }

    /// The scene's bounding box, ((x, y, z) min, (x, y, z) max).
    #[getter]
    fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let (lo, hi) = self.scene.bounds();
        (lo.to_array(), hi.to_array())
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

/// Loads a scene: `builtin:room`, or a Mitsuba .xml, glTF (.gltf/.glb), .ply or .obj file.
#[pyfunction]
pub fn load_scene(py: Python<'_>, spec: &str) -> PyResult<Scene> {
    let scene = py
        .detach(|| nprt_scene::load_scene(spec, &SceneOptions::default()))
        .or_py()?;
    Ok(Scene {
        spec: spec.to_string(),
        scene: Arc::new(scene),
        traced: OnceLock::new(),
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
    fn new(texels: PyArrayLike3<f32, AllowTypeChange>, name: &str) -> PyResult<Self> {
        let a = texels.as_array();
        let (h, w, c) = a.dim();
        if c != 3 {
            return Err(crate::error::NprtError::new_err(format!(
                "{name}: an environment map is an (H, 2H, 3) array, got shape ({h}, {w}, {c})"
            )));
        }
        let texels = a.iter().copied().collect::<Vec<f32>>();
        let texels = texels.chunks_exact(3).map(glam::Vec3::from_slice).collect();
        let map = nprt_scene::EnvMap::from_texels(name, w, h, texels).or_py()?;
        Ok(EnvMap { map })
    }

    /// Its texels as an (H, 2H, 3) float32 array.
    fn to_array<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f32>> {
        arrays::image(py, self.map.texels(), self.map.width(), self.map.height())
    }

    /// The same map turned by `degrees` about +Y (Mitsuba's `<rotate y="1" angle=.../>`).
    fn rotated(&self, degrees: f32) -> EnvMap {
        EnvMap {
            map: self.map.rotated_y(degrees),
        }
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
#[pyo3(signature = (origin, target, up = [0.0, 1.0, 0.0]))]
pub fn look_at<'py>(
    py: Python<'py>,
    origin: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (o, t, u) = (origin.into(), target.into(), up.into());
    if o == t {
        return Err(crate::error::NprtError::new_err(
            "a camera cannot look at its own origin",
        ));
    }
    Ok(arrays::matrix(
        py,
        nprt_scene::Camera::look_at(o, t, u, 60.0, 1, 1).to_world,
    ))
}

/// Opens an environment map: an .exr/.hdr file, `builtin:sky[:ELEV[:AZIM[:TURB]]]` or
/// `builtin:indoor[:SEED]`.
#[pyfunction]
pub fn open_envmap(py: Python<'_>, spec: &str) -> PyResult<EnvMap> {
    let map = py.detach(|| nprt_scene::open_envmap(spec)).or_py()?;
    Ok(EnvMap { map })
}

/// A path-traced frame of `scene` under `envmap` through `camera` (4 × 4 camera-to-world,
/// horizontal field of view `fov`), `spp` paths per pixel over the pixel (box filter), as
/// `nprt reference` renders: an (H, W, 3) float32 array of linear radiance.
#[pyfunction]
#[pyo3(signature = (scene, envmap, camera, width, height, fov = 60.0, spp = 64, seed = 0, max_depth = None))]
#[allow(clippy::too_many_arguments)]
pub fn reference<'py>(
    py: Python<'py>,
    scene: &Scene,
    envmap: &EnvMap,
    camera: PyArrayLike2<f32, AllowTypeChange>,
    width: u32,
    height: u32,
    fov: f32,
    spp: u32,
    seed: u64,
    max_depth: Option<u32>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let camera = arrays::camera(camera, fov, width, height).or_py()?;
    if spp == 0 {
        return Err(crate::error::NprtError::new_err(
            "samples per pixel must be at least 1",
        ));
    }
    let settings = RenderSettings {
        spp,
        max_depth: max_depth.or(scene.scene.max_depth),
        rr_depth: scene.scene.rr_depth,
        seed,
        filter: PixelFilter::Box,
        progress: false,
    };
    let map = &envmap.map;
    let frame = py.detach(|| render(scene.traced(), &camera, map, &settings));
    Ok(arrays::image(
        py,
        &frame.radiance,
        width as usize,
        height as usize,
    ))
}
