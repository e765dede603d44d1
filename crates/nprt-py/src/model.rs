//! A trained model from Python: loaded once on the CPU engine or the GPU kernels, its settings
//! as a dict, and frames of a scene under a map for any camera as numpy arrays.

use std::path::PathBuf;

use nprt_render::{Denoise, DirectSampling, FrameCache, Relighter, DEFAULT_DIRECT_SPP};

use crate::render::denoise_choice;
use nprt_net::Parameters;
use numpy::{IntoPyArray, PyArray3};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument;
use crate::arrays;
use crate::choice::engine_arg;
use crate::error::OrPy;
use crate::scene::{envmap_arg, scene_arg, Reduced, Scene};

/// The model folder `path` that `nprt train` wrote, ready to relight frames on `device` ("cpu",
/// "gpu", "wgpu" or "auto").
#[pyclass(frozen, module = "nprt")]
pub struct Model {
    dir: PathBuf,
    /// The device it was asked for, as given ("cpu", "gpu", …): what a pickled copy opens.
    asked: String,
    relighter: Relighter,
}

impl Model {
    /// A `UserWarning` where `scene` is not the scene the model was trained on (both hashes
    /// known and different).
    fn warn_if_foreign(&self, py: Python<'_>, scene: &Scene) -> PyResult<()> {
        let trained = self.relighter.file.scene_hash.as_str();
        match scene.hash() {
            Some(h) if !trained.is_empty() && h != trained => PyErr::warn(
                py,
                &py.get_type::<PyUserWarning>(),
                &std::ffi::CString::new(format!(
                    "model '{}' was trained on scene '{}', not on '{}' (hash {} ≠ {}): its \
                     frames of another scene are not meaningful",
                    self.dir.display(),
                    self.relighter.file.scene,
                    scene.spec,
                    &h[..12],
                    &trained[..12.min(trained.len())]
                ))?,
                1,
            ),
            _ => Ok(()),
        }
    }
}

#[pymethods]
impl Model {
    #[new]
    #[pyo3(signature = (path, device = None), text_signature = "(path, device='cpu')")]
    fn new(
        py: Python<'_>,
        path: &Bound<'_, PyAny>,
        device: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let path = argument::path(path, "path")?;
        let asked = argument::text_or_none(device, "device", "a str: cpu, gpu, wgpu or auto")?
            .unwrap_or_else(|| "cpu".into());
        let engine = engine_arg(device)?;
        let relighter = py.detach(|| Relighter::load(&path, engine)).or_py()?;
        Ok(Model {
            dir: path,
            asked,
            relighter,
        })
    }

    /// The model's settings and training record (its model.json) as a dict.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::json_file(py, &self.dir.join("model.json"))
    }

    /// What runs, in one line: the design, its basis and where its direct light comes from
    /// ("linear design on sh:2 (siren), direct light traced (16 spp, denoised by OIDN), level
    /// calibrated"), at `render`'s defaults.
    #[getter]
    fn description(&self) -> PyResult<String> {
        let denoiser = Denoise::default()
            .denoiser(&self.relighter, &self.dir)
            .or_py()?;
        Ok(self.relighter.describe(&DirectSampling {
            spp: DEFAULT_DIRECT_SPP,
            seed: 0,
            denoiser,
        }))
    }

    /// Where the networks run: "cpu", or the GPU adapter.
    #[getter]
    fn device(&self) -> String {
        self.relighter.networks_on()
    }

    /// A frame of `scene` under `envmap` turned by `rotation` degrees about +Y, through
    /// `camera` (4 × 4 camera-to-world, horizontal field of view `fov`) at `width` × `height`: the G-buffer, the
    /// networks, and the background (or, for a model trained with `--direct traced`, direct
    /// light traced with `direct_spp` paths per pixel from `seed`, denoised as `denoise_direct`
    /// says: True, False, "auto", "on" or "off"; None, auto: where OIDN is installed). An
    /// (H, W, 3) float32 array of linear radiance. The GIL is released while it renders.
    ///
    /// `scene` and `envmap` may be loaded objects or what names them (a `str` or a
    /// `pathlib.Path`). A scene other than the one the model was trained on (by its hash)
    /// renders with a warning (`UserWarning`): the networks know their own scene only.
    #[pyo3(signature = (
        scene, envmap, camera, width, height, fov = None, rotation = None, direct_spp = None,
        seed = None, denoise_direct = None
    ), text_signature = "(scene, envmap, camera, width, height, fov=60.0, rotation=0.0, \
        direct_spp=16, seed=0, denoise_direct=None)")]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        scene: &Bound<'py, PyAny>,
        envmap: &Bound<'py, PyAny>,
        camera: &Bound<'py, PyAny>,
        width: &Bound<'py, PyAny>,
        height: &Bound<'py, PyAny>,
        fov: Option<&Bound<'py, PyAny>>,
        rotation: Option<&Bound<'py, PyAny>>,
        direct_spp: Option<&Bound<'py, PyAny>>,
        seed: Option<&Bound<'py, PyAny>>,
        denoise_direct: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let (width, height) = arrays::frame_size(width, height)?;
        let camera = arrays::camera(camera, fov, width, height)?;
        let rotation =
            argument::number_or_none(rotation, "rotation", argument::FINITE)?.unwrap_or(0.0) as f32;
        let direct_spp = argument::whole_or_none(direct_spp, "direct_spp", 0..=u32::MAX)?
            .unwrap_or(DEFAULT_DIRECT_SPP);
        let seed = argument::whole_or_none(seed, "seed", 0..=u64::MAX)?.unwrap_or(0);
        let scene = scene_arg(scene, "scene")?;
        let envmap = envmap_arg(envmap, "envmap")?;
        let scene = scene.get();
        self.warn_if_foreign(py, scene)?;
        let denoise = denoise_choice(denoise_direct)?.unwrap_or_default();
        let sampling = DirectSampling {
            spp: direct_spp,
            seed,
            denoiser: denoise.denoiser(&self.relighter, &self.dir).or_py()?,
        };
        let map = &envmap.get().map;
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

    /// The network's radiance at the G-buffer `gbuffer` under `envmap` turned by `rotation`
    /// degrees about +Y: `gbuffer` is a dict of the dataset's own channels (`position`, `normal`,
    /// `view`, `kd`, `ks` as (H, W, 3) arrays, `alpha` and `mask` as (H, W); a `Dataset` view is
    /// one), and the result an (H, W, 3) float32 array, zero where `mask` is 0. What the networks
    /// predict, calibrated: for a model that traces its direct light, its indirect light only
    /// (`render` adds the traced direct light).
    #[pyo3(signature = (gbuffer, envmap, rotation = None))]
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        gbuffer: &Bound<'py, PyAny>,
        envmap: &Bound<'py, PyAny>,
        rotation: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let (g, w, h) = arrays::gbuffer(gbuffer)?;
        let rotation =
            argument::number_or_none(rotation, "rotation", argument::FINITE)?.unwrap_or(0.0) as f32;
        let envmap = envmap_arg(envmap, "envmap")?;
        let map = &envmap.get().map;
        let (rgb, _) = py
            .detach(|| self.relighter.shade(&g, (map, rotation)))
            .or_py()?;
        Ok(arrays::image(py, &rgb, w, h))
    }

    /// The network's weights as a dict of float32 arrays by tensor name (as the weights file
    /// names them), each of its own shape.
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (_, net) = py.detach(|| nprt_net::load_model(&self.dir)).or_py()?;
        let out = PyDict::new(py);
        let mut failed = None;
        net.visit("", &mut |name, shape, values| {
            let array = numpy::ndarray::ArrayD::from_shape_vec(shape.to_vec(), values.to_vec())
                .expect("a tensor of its shape");
            if let Err(e) = out.set_item(name, array.into_pyarray(py)) {
                failed.get_or_insert(e);
            }
        });
        failed.map_or(Ok(out), Err)
    }

    /// The light code of `envmap` turned by `rotation` degrees about +Y, as the shading networks
    /// read it: a dict with `code` (the encoder's 64 values, or for the linear design the map's
    /// projection on its basis, (K, 3): coefficient k of each colour channel) and `scale` (what
    /// each channel of the map was divided by first; the radiance is multiplied by it again).
    #[pyo3(signature = (envmap, rotation = None), text_signature = "($self, envmap, rotation=0.0)")]
    fn light_code<'py>(
        &self,
        py: Python<'py>,
        envmap: &Bound<'py, PyAny>,
        rotation: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let rotation =
            argument::number_or_none(rotation, "rotation", argument::FINITE)?.unwrap_or(0.0) as f32;
        let envmap = envmap_arg(envmap, "envmap")?;
        let map = &envmap.get().map;
        let (code, scale, linear) = py
            .detach(|| {
                let (file, net) = nprt_net::load_model(&self.dir)?;
                let input = file.config.light_input(map, rotation);
                let code = net
                    .light
                    .forward(&input.pixels, input.width)
                    .codes()
                    .to_vec();
                anyhow::Ok((code, input.scale, file.config.design.reads_basis()))
            })
            .or_py()?;
        let out = PyDict::new(py);
        let code = match linear {
            true => numpy::ndarray::Array2::from_shape_vec((code.len() / 3, 3), code)
                .expect("3 values a coefficient")
                .into_pyarray(py)
                .into_any(),
            false => code.into_pyarray(py).into_any(),
        };
        out.set_item("code", code)?;
        out.set_item("scale", scale.to_vec().into_pyarray(py))?;
        Ok(out)
    }

    /// Pickled by its folder and device (a worker process loads it again).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Reduced<'py, (PathBuf, String)>> {
        let class = py.import("nprt")?.getattr("Model")?;
        Ok((class, (self.dir.clone(), self.asked.clone())))
    }

    fn __repr__(&self) -> String {
        format!(
            "nprt.Model('{}' on {})",
            self.dir.display(),
            self.relighter.networks_on()
        )
    }
}
