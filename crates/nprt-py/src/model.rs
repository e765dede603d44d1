//! A trained model from Python: loaded once on the CPU engine or the GPU kernels, its settings
//! as a dict, and frames of a scene under a map for any camera as numpy arrays.

use std::path::PathBuf;

use nprt_render::{DirectSampling, FrameCache, Relighter};
use numpy::{AllowTypeChange, PyArray3, PyArrayLike2};
use pyo3::prelude::*;

use crate::arrays;
use crate::choice::engine;
use crate::error::OrPy;
use crate::scene::{EnvMap, Scene};

/// A model folder `nprt train` wrote, ready to relight frames on `device`.
#[pyclass(frozen, module = "nprt")]
pub struct Model {
    dir: PathBuf,
    relighter: Relighter,
}

#[pymethods]
impl Model {
    #[new]
    #[pyo3(signature = (path, device = "cpu"))]
    fn new(py: Python<'_>, path: PathBuf, device: &str) -> PyResult<Self> {
        let engine = engine(device)?;
        let relighter = py.detach(|| Relighter::load(&path, engine)).or_py()?;
        Ok(Model {
            dir: path,
            relighter,
        })
    }

    /// The model's settings and training record (its model.json) as a dict.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::json_file(py, &self.dir.join("model.json"))
    }

    /// Where the networks run: "cpu", or the GPU adapter.
    #[getter]
    fn device(&self) -> String {
        self.relighter.networks_on()
    }

    /// A frame of `scene` under `envmap` turned by `rotation` degrees about +Y, through
    /// `camera` (4 × 4 camera-to-world, horizontal field of view `fov`): the G-buffer, the
    /// networks, and the background (or, for a model trained with `--direct traced`, direct
    /// light traced with `direct_spp` paths per pixel from `seed`). An (H, W, 3) float32 array
    /// of linear radiance. The GIL is released while it renders.
    #[pyo3(signature = (scene, envmap, camera, width, height, fov = 60.0, rotation = 0.0, direct_spp = 16, seed = 0))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        scene: &Scene,
        envmap: &EnvMap,
        camera: PyArrayLike2<f32, AllowTypeChange>,
        width: u32,
        height: u32,
        fov: f32,
        rotation: f32,
        direct_spp: u32,
        seed: u64,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let camera = arrays::camera(camera, fov, width, height).or_py()?;
        let sampling = DirectSampling {
            spp: direct_spp,
            seed,
            denoiser: None,
        };
        let map = &envmap.map;
        let (rgb, _) = py
            .detach(|| {
                let mut cache = FrameCache::default();
                let ts = scene.traced();
                self.relighter
                    .frame(&mut cache, ts, &camera, map, rotation, (), sampling)
            })
            .or_py()?;
        Ok(arrays::image(py, &rgb, width as usize, height as usize))
    }

    fn __repr__(&self) -> String {
        format!(
            "nprt.Model('{}' on {})",
            self.dir.display(),
            self.relighter.networks_on()
        )
    }
}
