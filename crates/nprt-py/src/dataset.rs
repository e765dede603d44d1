//! A dataset folder opened from Python: its manifest as a dict, each view's images (radiance,
//! its direct part, every G-buffer channel) as numpy arrays and its camera as a 4 × 4 matrix.

use std::path::PathBuf;

use nprt_data::dataset::{load_manifest, load_manifest_hashed, read_view, Manifest, PackedDataset};
use pyo3::exceptions::PyIndexError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySlice};

use crate::arrays::{self, CameraOut};
use crate::choice::named;
use crate::error::OrPy;

/// The dataset `nprt generate` wrote in the folder `path` (docs/dataset.md), checked as every
/// command checks it.
#[pyclass(frozen, module = "nprt")]
pub struct Dataset {
    dir: PathBuf,
    manifest: Manifest,
}

impl Dataset {
    /// How view `v` is lit: its map (the spec), its turn about +Y and its RGB gain, and the
    /// maps added to it (`mix_maps`).
    fn lighting<'py>(
        &self,
        py: Python<'py>,
        v: &nprt_data::dataset::ViewRecord,
    ) -> PyResult<Bound<'py, PyAny>> {
        let maps = &self.manifest.settings.envmaps;
        let spec = |k: usize| maps.get(k).map(|m| m.spec.clone());
        let mix: Vec<_> = v
            .mix
            .iter()
            .map(|t| serde_json::json!({"map": spec(t.map), "rotation_deg": t.rotation_deg, "gain": t.gain}))
            .collect();
        let value = serde_json::json!({
            "map": spec(v.map),
            "rotation_deg": v.rotation_deg,
            "gain": v.gain,
            "mix": mix,
        });
        arrays::json(py, &value)
    }

    /// View `index`'s images and record as [`Dataset::view_py`] gives them.
    fn view<'py>(&self, py: Python<'py>, index: usize) -> PyResult<Bound<'py, PyDict>> {
        let v = self.record(index)?;
        let parts = self.manifest.settings.parts(v);
        let path = self.dir.join(&v.file);
        let image = py.detach(|| read_view(&path, v, parts)).or_py()?;
        let (w, h) = (v.width as usize, v.height as usize);
        let (f, g) = (&image.frame, &image.frame.gbuffer);
        let out = PyDict::new(py);
        for (name, rgb) in [
            ("radiance", &f.radiance),
            ("direct", &f.direct),
            ("position", &g.position),
            ("normal", &g.normal),
            ("view", &g.view),
            ("kd", &g.kd),
            ("ks", &g.ks),
        ] {
            out.set_item(name, arrays::image(py, rgb, w, h))?;
        }
        out.set_item("alpha", arrays::plane(py, &g.alpha, w, h))?;
        out.set_item("mask", arrays::plane(py, &g.mask, w, h))?;
        if let Some(half) = &image.half {
            out.set_item("half", arrays::image(py, half, w, h))?;
        }
        if let Some(t) = &image.transfer {
            let k = t.basis.coefficients();
            out.set_item("transfer", arrays::coefficients(py, &t.all, w, h, k))?;
            out.set_item(
                "transfer_direct",
                arrays::coefficients(py, &t.direct, w, h, k),
            )?;
        }
        out.set_item("lighting", self.lighting(py, v)?)?;
        out.set_item("index", index)?;
        out.set_item("split", &v.split)?;
        Ok(out)
    }

    /// The view `obj` names for [`Dataset::view_py`] and [`Dataset::camera`]: a whole number
    /// (an InputError otherwise), negative from the end; one past either end is an IndexError,
    /// as a sequence's.
    fn index_arg(&self, obj: &Bound<'_, PyAny>) -> PyResult<usize> {
        let len = self.manifest.views.len() as i128;
        let i: i128 = crate::argument::whole(obj, "index", i128::MIN..=i128::MAX)?;
        if !(-len..len).contains(&i) {
            return Err(PyIndexError::new_err(format!(
                "index={i}: a dataset of {len} views has views 0 to {} (or -{len} to -1)",
                len - 1
            )));
        }
        Ok(if i < 0 { i + len } else { i } as usize)
    }

    fn record(&self, index: usize) -> PyResult<&nprt_data::dataset::ViewRecord> {
        self.manifest.views.get(index).ok_or_else(|| {
            PyIndexError::new_err(format!(
                "view {index} of a dataset of {}",
                self.manifest.views.len()
            ))
        })
    }
}

#[pymethods]
impl Dataset {
    #[new]
    fn new(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<Self> {
        let path = crate::argument::path(path, "path")?;
        let manifest = py.detach(|| load_manifest(&path)).or_py()?;
        Ok(Dataset {
            dir: path,
            manifest,
        })
    }

    /// Views in all (training views first, then test views).
    fn __len__(&self) -> usize {
        self.manifest.views.len()
    }

    /// The manifest (settings, scene bounds, one record per view) as a dict.
    #[getter]
    fn manifest<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let value = serde_json::to_value(&self.manifest).expect("a manifest serialises");
        arrays::json(py, &value)
    }

    /// The indices of the views of `split` ("train" or "test"; another name is a ValueError).
    fn split(&self, split: &Bound<'_, PyAny>) -> PyResult<Vec<usize>> {
        let rule = "must be 'train' or 'test'";
        let name = crate::argument::text(split, "split", "a str: 'train' or 'test'")?;
        if !["train", "test"].contains(&name.as_str()) {
            return Err(crate::argument::refused(split, "split", rule));
        }
        let split = name.as_str();
        Ok((self.manifest.views.iter().enumerate())
            .filter(|(_, v)| v.split == split)
            .map(|(i, _)| i)
            .collect())
    }

    /// View `index`'s images (negative counts from the end), each an (H, W, 3) or (H, W)
    /// float32 array: `radiance`, `direct`, `position`, `normal`, `view`, `kd`, `ks`, `alpha`,
    /// `mask`, and for a test view rendered in halves `half` (the first half's radiance); for a
    /// training view of a dataset made with `transfer="sh:L"`, `transfer` and
    /// `transfer_direct`, (H, W, K, 3) arrays of its K = (L+1)² coefficients per colour
    /// channel (all light and its direct part); with its `index`, `split` and `lighting`
    /// (`map`, `rotation_deg`, `gain`, and `mix`: the maps added to it).
    #[pyo3(name = "view")]
    fn view_py<'py>(
        &self,
        py: Python<'py>,
        index: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let index = self.index_arg(index)?;
        self.view(py, index)
    }

    /// View `key` as [`Dataset::view`] gives it (negative indices count from the end), or a
    /// list of them for a slice: `ds[0]`, `ds[-1]`, `ds[:4]`.
    fn __getitem__<'py>(
        &self,
        py: Python<'py>,
        key: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let len = self.manifest.views.len();
        if let Ok(slice) = key.cast::<PySlice>() {
            let ix = slice.indices(len as isize)?;
            let views = (0..ix.slicelength)
                .map(|k| self.view(py, (ix.start + k as isize * ix.step) as usize))
                .collect::<PyResult<Vec<_>>>()?;
            return Ok(PyList::new(py, views)?.into_any());
        }
        let i: isize = key
            .extract()
            .map_err(|_| crate::error::input_error("a dataset is indexed by an int or a slice"))?;
        let index = if i < 0 { i + len as isize } else { i };
        if index < 0 {
            return Err(PyIndexError::new_err(format!(
                "view {i} of a dataset of {len}"
            )));
        }
        Ok(self.view(py, index as usize)?.into_any())
    }

    /// Every view in order, as [`Dataset::view`] gives it (each read when reached).
    fn __iter__(slf: Bound<'_, Self>) -> DatasetViews {
        DatasetViews {
            dataset: slf.unbind(),
            next: 0,
        }
    }

    /// View `index`'s camera (negative counts from the end): (4 × 4 camera-to-world matrix, horizontal field of view in
    /// degrees, (width, height)).
    fn camera<'py>(&self, py: Python<'py>, index: &Bound<'py, PyAny>) -> PyResult<CameraOut<'py>> {
        let v = self.record(self.index_arg(index)?)?;
        let c = v.camera();
        Ok((
            arrays::matrix(py, c.to_world),
            v.fov_x_deg,
            (v.width, v.height),
        ))
    }

    /// Reads every view back: `views`, `complete`, and the files `missing`, `corrupt` (with the
    /// bad texel), `leftovers` (temporary files of killed runs) and `packs`, as
    /// `nprt dataset verify` lists them.
    fn verify<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = py
            .detach(|| nprt_data::dataset::verify(&self.dir))
            .or_py()?;
        let out = PyDict::new(py);
        out.set_item("views", r.views)?;
        out.set_item("complete", r.complete)?;
        out.set_item("missing", r.missing)?;
        out.set_item("corrupt", r.corrupt)?;
        out.set_item("leftovers", r.leftovers)?;
        out.set_item("packs", r.packs)?;
        Ok(out)
    }

    /// Packs the dataset for training (`direct` "learned" or "traced", as `nprt train
    /// --direct`), or checks the pack already there, as `nprt dataset pack` (with a progress
    /// bar unless `progress` is False); returns its path, its records and its bytes.
    #[pyo3(signature = (direct = None, progress = None), text_signature = "(direct='learned', progress=True)")]
    fn pack<'py>(
        &self,
        py: Python<'py>,
        direct: Option<&Bound<'py, PyAny>>,
        progress: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let direct: nprt_net::DirectLight = named(direct, "direct")?.unwrap_or_default();
        let progress = crate::argument::flag_or(progress, "progress", true)?;
        let target = direct.packed_target();
        let (path, records, bytes) = py
            .detach(|| {
                let (manifest, hash) = load_manifest_hashed(&self.dir)?;
                let pack = PackedDataset::open_or_pack(
                    &self.dir,
                    &manifest,
                    &hash,
                    target,
                    progress,
                    |why| {
                        if progress {
                            eprintln!("{why}")
                        }
                    },
                )?;
                anyhow::Ok((
                    PackedDataset::path(&self.dir, target),
                    pack.records().len(),
                    pack.bytes(),
                ))
            })
            .or_py()?;
        let out = PyDict::new(py);
        out.set_item("path", path)?;
        out.set_item("records", records)?;
        out.set_item("bytes", bytes)?;
        Ok(out)
    }

    fn __repr__(&self) -> String {
        let s = &self.manifest.settings;
        format!(
            "nprt.Dataset('{}', {} training and {} test views of '{}')",
            self.dir.display(),
            s.train_views,
            s.test_views,
            s.scene
        )
    }
}

/// The views of a dataset one by one (`for view in dataset`).
#[pyclass(module = "nprt")]
pub struct DatasetViews {
    dataset: Py<Dataset>,
    next: usize,
}

#[pymethods]
impl DatasetViews {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let dataset = self.dataset.bind(py).get();
        if self.next >= dataset.manifest.views.len() {
            return Ok(None);
        }
        self.next += 1;
        dataset.view(py, self.next - 1).map(Some)
    }
}
