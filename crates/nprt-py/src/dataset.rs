//! A dataset folder opened from Python: its manifest as a dict, each view's images (radiance,
//! its direct part, every G-buffer channel) as numpy arrays and its camera as a 4 × 4 matrix.

use std::path::PathBuf;

use nprt_data::dataset::{load_manifest, load_manifest_hashed, read_view, Manifest, PackedDataset};
use pyo3::exceptions::PyIndexError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PySlice};

use crate::arrays::{self, CameraOut};
use crate::choice::parse;
use crate::error::OrPy;

/// A dataset `nprt generate` wrote (docs/dataset.md), checked as every command checks it.
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
    fn new(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
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
    fn split(&self, split: &str) -> PyResult<Vec<usize>> {
        if !["train", "test"].contains(&split) {
            return Err(crate::error::input_error(format!(
                "split must be 'train' or 'test', not '{split}'"
            )));
        }
        Ok((self.manifest.views.iter().enumerate())
            .filter(|(_, v)| v.split == split)
            .map(|(i, _)| i)
            .collect())
    }

    /// View `index`'s images, each an (H, W, 3) or (H, W) float32 array: `radiance`, `direct`,
    /// `position`, `normal`, `view`, `kd`, `ks`, `alpha`, `mask`, and for a test view rendered
    /// in halves `half` (the first half's radiance); with its `index`, `split` and `lighting`
    /// (`map`, `rotation_deg`, `gain`, and `mix`: the maps added to it).
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
        out.set_item("lighting", self.lighting(py, v)?)?;
        out.set_item("index", index)?;
        out.set_item("split", &v.split)?;
        Ok(out)
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

    /// View `index`'s camera: (4 × 4 camera-to-world matrix, horizontal field of view in
    /// degrees, (width, height)).
    fn camera<'py>(&self, py: Python<'py>, index: usize) -> PyResult<CameraOut<'py>> {
        let v = self.record(index)?;
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
    /// --direct`), or checks the pack already there, as `nprt dataset pack`; returns its path,
    /// its records and its bytes.
    #[pyo3(signature = (direct = "learned", progress = true))]
    fn pack<'py>(
        &self,
        py: Python<'py>,
        direct: &str,
        progress: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let direct: nprt_net::DirectLight = parse(direct)?;
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
                    |why| eprintln!("{why}"),
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
