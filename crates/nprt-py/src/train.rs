//! `nprt.train`: `nprt train` from Python, its defaults the library's (`TrainOptions`,
//! `ModelConfig`).

use std::sync::Mutex;

use nprt_net::deep_shading::{self, DeepShadingOptions};
use nprt_net::training::loss_curves::LossRow;
use nprt_net::training::snapshot::Snapshot;
use nprt_net::training::training_set::TrainingSet;
use nprt_net::{Asked, Calibration, RunLength, TrainOptions, TrainSummary, Watch};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::argument;
use crate::choice::{engine_arg, named};
use crate::error::OrPy;

/// Trains `arch` (one of `nprt.DESIGNS`, with its own defaults; None: the recommended recipe,
/// nprt's measured best, as `nprt train` without `--arch`) on the dataset `data` into the model
/// folder `out` (a run already there with the same settings is resumed, and a larger `epochs`
/// or `minutes` continues a finished one), on `device`, for `minutes` of training time and/or
/// `epochs` passes (without either: 20 epochs), from `seed`, with a progress bar unless
/// `progress` is False. `None` takes `nprt train`'s default, as for `activation` ("siren" or
/// "relu"), `precision` ("f32" or "f16"), `batch_size`, `lr` (the learning rate) and
/// `schedule` (the learning rate's: "paper" or "cosine"). Returns
/// the run: `epochs`, `steps`, `samples_per_s`, `train_loss`, `val_loss`, `seconds`,
/// `steps_on` and `resumed_from_epoch`; the loss curves are in `out`/loss.csv.
///
/// `snapshots` keeps the model at points of the run (`"1m,2m,4m"`: minutes of training time
/// as `Nm`, epochs as `N`), each a model folder in `out`/snapshots/POINT (`nprt train
/// --snapshots`).
///
/// `basis` is the linear design's light basis, `"sh:L"` or `"learned:K"` (`nprt train
/// --basis`; only for the linear design); `direct` ("learned" or "traced"), `calibrate`
/// ("none" or "level") and `targets` ("radiance" or "transfer") are `nprt train`'s flags of
/// those names, each None for the recipe's choice or the named design's default.
///
/// `callback`, where given, is called at each epoch's end with that epoch's row of the loss
/// curves (`step`, `epoch`, `samples`, `seconds`, `train_loss`, `val_loss`); returning a false
/// value (False, 0, numpy's False_: anything whose `bool` is False, None aside) ends the run
/// there; returning nothing goes on. Ctrl-C ends it there too, then raises `nprt.Interrupted` (a KeyboardInterrupt).
/// Either way the
/// run is saved as at the end of a time budget, and the same call resumes it. The GIL is
/// released while it trains.
#[pyfunction]
#[pyo3(signature = (
    data, arch = None, out = None, *, minutes = None, epochs = None, activation = None,
    device = None, precision = None, batch_size = None, lr = None, schedule = None, seed = None,
    progress = None, callback = None, basis = None, snapshots = None, targets = None,
    direct = None, calibrate = None
), text_signature = "(data, arch=None, out=None, *, minutes=None, epochs=None, activation=None, \
    device='cpu', precision=None, batch_size=None, lr=None, schedule=None, seed=None, \
    progress=True, callback=None, basis=None, snapshots=None, targets=None, direct=None, \
    calibrate=None)")]
#[allow(clippy::too_many_arguments)]
pub fn train<'py>(
    py: Python<'py>,
    data: &Bound<'py, PyAny>,
    arch: Option<&Bound<'py, PyAny>>,
    out: Option<&Bound<'py, PyAny>>,
    minutes: Option<&Bound<'py, PyAny>>,
    epochs: Option<&Bound<'py, PyAny>>,
    activation: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
    precision: Option<&Bound<'py, PyAny>>,
    batch_size: Option<&Bound<'py, PyAny>>,
    lr: Option<&Bound<'py, PyAny>>,
    schedule: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
    callback: Option<Bound<'py, PyAny>>,
    basis: Option<&Bound<'py, PyAny>>,
    snapshots: Option<&Bound<'py, PyAny>>,
    targets: Option<&Bound<'py, PyAny>>,
    direct: Option<&Bound<'py, PyAny>>,
    calibrate: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let data = argument::path(data, "data")?;
    let out = argument::path_or_none(out, "out")?
        .ok_or_else(|| crate::error::input_error("out=None: give the model folder to write"))?;
    let callback = argument::callable_or_none(callback, "callback")?;
    let progress = argument::flag_or(progress, "progress", true)?;
    let asked = Asked {
        design: named(arch, "arch")?,
        activation: named(activation, "activation")?,
        direct: named(direct, "direct")?,
        basis: named(basis, "basis")?,
        calibration: named(calibrate, "calibrate")?,
        targets: named(targets, "targets")?,
    };
    let config = asked.config().or_py()?;
    let run = RunLength {
        epochs: argument::whole_or_none(epochs, "epochs", 1..=usize::MAX)?,
        minutes: minutes_or_none(minutes, "minutes")?,
        lr_schedule: named(schedule, "schedule")?,
    };
    let lr = argument::number_or_none(lr, "lr", f64::MIN_POSITIVE..=f64::MAX)?;
    let keywords = [seed, batch_size, precision, snapshots];
    let opts = options(keywords, progress, asked.calibration())?.with_run(config.design, run, lr);
    let engine = engine_arg(device)?;
    let watch = EpochWatch::new(callback);
    let (summary, _) = py
        .detach(|| {
            opts.check()?;
            let set = TrainingSet::load(&data, &config, progress, |why| {
                if progress {
                    eprintln!("{why}")
                }
            })?;
            let opts = TrainOptions {
                targets: asked.targets(&config, set.manifest.settings.transfer),
                ..opts
            };
            nprt_net::train(
                &set,
                &config,
                &opts,
                &out,
                engine,
                Watch::epochs(&|r| watch.hear(r)),
            )
        })
        .or_py()?;
    watch.finish()?;
    let s = summary_dict(py, &summary)?;
    Ok(s)
}

/// The run's options from `train`'s keywords `seed`, `batch_size`, `precision` and
/// `snapshots`, each the default where None.
fn options(
    [seed, batch_size, precision, snapshots]: [Option<&Bound<'_, PyAny>>; 4],
    progress: bool,
    calibration: Calibration,
) -> PyResult<TrainOptions> {
    let d = TrainOptions::default();
    let snapshots = argument::text_or_none(snapshots, "snapshots", "a str such as \"1m,2m,4m\"")?;
    Ok(TrainOptions {
        schedule: nprt_net::Schedule {
            seed: argument::whole_or_none(seed, "seed", 0..=u64::MAX)?.unwrap_or(d.schedule.seed),
            progress,
            snapshots: (snapshots.as_deref().map(Snapshot::parse_list).transpose())
                .map_err(|e| crate::error::input_error(format!("snapshots={snapshots:?}: {e}")))?
                .unwrap_or_default(),
            ..d.schedule
        },
        batch_size: argument::whole_or_none(batch_size, "batch_size", 1..=usize::MAX)?
            .unwrap_or(d.batch_size),
        precision: named(precision, "precision")?.unwrap_or(d.precision),
        calibration,
        ..d
    })
}

/// Minutes of training time, as `nprt train --minutes` takes them ([`nprt_net::check_minutes`]).
fn minutes_or_none(obj: Option<&Bound<'_, PyAny>>, arg: &str) -> PyResult<Option<f64>> {
    let range = nprt_net::MIN_MINUTES..=nprt_net::MAX_MINUTES;
    argument::number_or_none(obj, arg, range)
}

/// Trains the Deep Shading baseline (Nalbach et al. 2017, a U-Net on G-buffer images) on
/// `data` into `out`, on `device` as for [`train`], as `nprt train-deep-shading`; `minutes`, `epochs`,
/// `schedule`, `lr`, `seed`, `progress` and `callback` as for [`train`]; `batch_views` views
/// per batch. Returns what [`train`] returns, and `unet_params` and `encoder_params`.
#[pyfunction]
#[pyo3(signature = (
    data, out, *, minutes = None, epochs = None, schedule = None, lr = None, seed = None,
    batch_views = None, device = None, progress = None, callback = None
), text_signature = "(data, out, *, minutes=None, epochs=None, schedule=None, lr=None, \
    seed=None, batch_views=None, device='cpu', progress=True, callback=None)")]
#[allow(clippy::too_many_arguments)]
pub fn train_deep_shading<'py>(
    py: Python<'py>,
    data: &Bound<'py, PyAny>,
    out: &Bound<'py, PyAny>,
    minutes: Option<&Bound<'py, PyAny>>,
    epochs: Option<&Bound<'py, PyAny>>,
    schedule: Option<&Bound<'py, PyAny>>,
    lr: Option<&Bound<'py, PyAny>>,
    seed: Option<&Bound<'py, PyAny>>,
    batch_views: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
    callback: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (data, out) = (argument::path(data, "data")?, argument::path(out, "out")?);
    let callback = argument::callable_or_none(callback, "callback")?;
    let engine = engine_arg(device)?;
    let d = DeepShadingOptions::default();
    let lr = argument::number_or_none(lr, "lr", f64::MIN_POSITIVE..=f64::MAX)?;
    let run = RunLength {
        epochs: argument::whole_or_none(epochs, "epochs", 1..=usize::MAX)?,
        minutes: minutes_or_none(minutes, "minutes")?,
        lr_schedule: named(schedule, "schedule")?,
    };
    let opts = DeepShadingOptions {
        schedule: run.apply(nprt_net::Schedule {
            learning_rate: lr.unwrap_or(d.schedule.learning_rate),
            seed: argument::whole_or_none(seed, "seed", 0..=u64::MAX)?.unwrap_or(d.schedule.seed),
            progress: argument::flag_or(progress, "progress", true)?,
            ..d.schedule
        }),
        batch_views: argument::whole_or_none(batch_views, "batch_views", 1..=usize::MAX)?
            .unwrap_or(d.batch_views),
        ..d
    };
    let watch = EpochWatch::new(callback);
    let (summary, file) = py
        .detach(|| {
            deep_shading::train(
                &data,
                &opts,
                engine,
                &out,
                Watch::epochs(&|r| watch.hear(r)),
            )
        })
        .or_py()?;
    watch.finish()?;
    let s = summary_dict(py, &summary)?;
    s.set_item("unet_params", file.unet_params)?;
    s.set_item("encoder_params", file.encoder_params)?;
    Ok(s)
}

/// A run's epoch ends heard for Python: the callback's answer (False stops the run), Ctrl-C
/// (stops it), and what stopped it, raised once the run is saved.
struct EpochWatch {
    callback: Option<Py<PyAny>>,
    stopped: Mutex<Option<PyErr>>,
}

impl EpochWatch {
    fn new(callback: Option<Py<PyAny>>) -> Self {
        EpochWatch {
            callback,
            stopped: Mutex::new(None),
        }
    }

    /// Whether the run goes on after the epoch that `row` ends.
    fn hear(&self, row: &LossRow) -> bool {
        Python::attach(|py| {
            let go_on = crate::error::check_interrupt(py).and_then(|()| match &self.callback {
                None => Ok(true),
                // No answer (None) goes on; any other by its truth (False, 0, numpy's
                // False_ stop).
                Some(f) => {
                    let answer = f.call1(py, (row_dict(py, row)?,))?;
                    let answer = answer.bind(py);
                    Ok(answer.is_none() || answer.is_truthy()?)
                }
            });
            go_on.unwrap_or_else(|e| {
                *self.stopped.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
                false
            })
        })
    }

    /// The exception that stopped the run, if one did.
    fn finish(self) -> PyResult<()> {
        match self.stopped.into_inner().unwrap_or_else(|p| p.into_inner()) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// A run's summary as both trainings return it.
fn summary_dict<'py>(py: Python<'py>, summary: &TrainSummary) -> PyResult<Bound<'py, PyDict>> {
    let s = PyDict::new(py);
    s.set_item("epochs", summary.epochs)?;
    s.set_item("steps", summary.steps)?;
    s.set_item("seconds", summary.seconds)?;
    s.set_item(
        "samples_per_s",
        summary.samples as f64 / summary.seconds.max(1e-9),
    )?;
    s.set_item("train_loss", summary.final_train)?;
    s.set_item("val_loss", summary.final_val)?;
    s.set_item("steps_on", summary.steps_on.as_str())?;
    s.set_item("resumed_from_epoch", summary.resumed_from_epoch)?;
    Ok(s)
}

/// A row of the loss curves as the callback gets it.
fn row_dict<'py>(py: Python<'py>, row: &LossRow) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("step", row.step)?;
    d.set_item("epoch", row.epoch)?;
    d.set_item("samples", row.samples)?;
    d.set_item("seconds", row.seconds)?;
    d.set_item("train_loss", row.train)?;
    d.set_item("val_loss", row.val)?;
    Ok(d)
}
