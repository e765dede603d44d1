//! Training as the paper does it: Adam at 1e-4, L1 on log(1 + x), encoder trained jointly,
//! batches that mix foreground pixels of several views, each lit by its own rotated map.
//!
//! A run lives in its model folder: the model (config and latest weights), `loss.csv`,
//! `loss.png` and `checkpoint/`. Checkpoints are written atomically and a re-run with the same
//! settings resumes exactly where the last one stopped: batch order is a function of the seed
//! and the epoch, and parameter ids (which key Adam's state) are stable.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};
use burn::module::Module;
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::tensor::{Device, Int, Tensor, TensorData};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::data::{TrainingSet, ViewSamples};
use crate::design::{NprtNet, FEATURES};
use crate::layers::Init;
use crate::loss::log_l1;
use crate::model::{
    load_weights, save_model, save_weights, ModelConfig, ModelFile, MODEL_FORMAT, MODEL_VERSION,
};

/// Hyper-parameters and run options of `nprt train`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainOptions {
    pub epochs: usize,
    pub batch_size: usize,
    pub learning_rate: f64,
    pub seed: u64,
    /// Views whose pixels are mixed in one batch.
    pub views_per_batch: usize,
    /// Test-view pixels used for the per-epoch validation loss.
    pub val_samples: usize,
    /// Seconds between checkpoints inside an epoch (one is always written at each epoch end).
    #[serde(skip)]
    pub checkpoint_secs: f64,
    #[serde(skip)]
    pub progress: bool,
}

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            epochs: 20,
            batch_size: 16_384,
            learning_rate: 1e-4,
            seed: 0,
            views_per_batch: 8,
            val_samples: 65_536,
            checkpoint_secs: 300.0,
            progress: true,
        }
    }
}

impl TrainOptions {
    /// Whether a checkpoint made with `other` can be resumed with these options: everything
    /// that shapes the run must match; epochs may grow, reporting options may change.
    fn same_run(&self, other: &TrainOptions) -> bool {
        let key = |o: &TrainOptions| {
            (
                o.batch_size,
                o.learning_rate.to_bits(),
                o.seed,
                o.views_per_batch,
                o.val_samples,
            )
        };
        key(self) == key(other)
    }
}

/// One row of loss.csv.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct LossRow {
    pub step: u64,
    /// Epochs done, fractional.
    pub epoch: f64,
    pub samples: u64,
    pub seconds: f64,
    /// Mean training loss since the previous row.
    pub train: Option<f64>,
    /// Validation loss (at epoch ends).
    pub val: Option<f64>,
}

/// Resumable state, written last (atomically) so it never names files that do not exist.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Checkpoint {
    config: ModelConfig,
    options: TrainOptions,
    dataset_hash: String,
    epoch: usize,
    /// Next batch within `epoch`.
    batch: usize,
    step: u64,
    samples: u64,
    seconds: f64,
    history: Vec<LossRow>,
    weights: String,
    optimizer: String,
}

/// What a finished (or resumed and finished) run reports.
pub struct TrainSummary {
    pub steps: u64,
    pub samples: u64,
    pub seconds: f64,
    pub final_train: f64,
    pub final_val: f64,
    pub resumed_from_epoch: Option<f64>,
}

const CHECKPOINT_DIR: &str = "checkpoint";
const STATE_FILE: &str = "state.json";
const TRAIN_ROWS_PER_EPOCH: u64 = 20;

/// How the views of one epoch are grouped and how many batches each group gives.
struct EpochPlan {
    groups: Vec<Vec<usize>>,
    batches: Vec<usize>,
}

impl EpochPlan {
    fn new(set: &TrainingSet, opts: &TrainOptions, epoch: usize) -> Self {
        let mut order: Vec<usize> = (0..set.train.len())
            .filter(|&v| !set.train[v].is_empty())
            .collect();
        order.shuffle(&mut rng_for(opts.seed, epoch as u64, u64::MAX));
        let groups: Vec<Vec<usize>> = order
            .chunks(opts.views_per_batch.max(1))
            .map(<[usize]>::to_vec)
            .collect();
        let batches = groups
            .iter()
            .map(|g| {
                let n: usize = g.iter().map(|&v| set.train[v].len()).sum();
                n.div_ceil(opts.batch_size)
            })
            .collect();
        EpochPlan { groups, batches }
    }

    fn total(&self) -> usize {
        self.batches.iter().sum()
    }
}

fn rng_for(seed: u64, epoch: u64, group: u64) -> Pcg64Mcg {
    let key = [seed, epoch, group].map(u64::to_le_bytes).concat();
    let h = blake3::hash(&key);
    Pcg64Mcg::seed_from_u64(u64::from_le_bytes(h.as_bytes()[..8].try_into().unwrap()))
}

/// A batch in host memory: samples drawn from several views, and those views' maps.
pub struct Batch {
    pub features: Vec<f32>,
    pub radiance: Vec<f32>,
    /// Index into `lights` of each sample.
    pub view: Vec<i64>,
    pub scale: Vec<f32>,
    /// [V, 3, W/2, W] pre-processed maps.
    pub lights: Vec<f32>,
    /// W of the maps.
    pub light_width: usize,
}

impl Batch {
    /// Gathers `samples` ((view position in `views`, pixel) pairs) from `views`.
    pub fn gather(views: &[&ViewSamples], samples: &[(u32, u32)]) -> Self {
        let mut b = Batch {
            features: Vec::with_capacity(samples.len() * FEATURES),
            radiance: Vec::with_capacity(samples.len() * 3),
            view: Vec::with_capacity(samples.len()),
            scale: Vec::with_capacity(samples.len()),
            lights: views
                .iter()
                .flat_map(|v| v.light.pixels.iter().copied())
                .collect(),
            light_width: views.first().map_or(0, |v| v.light.width),
        };
        for &(v, p) in samples {
            let (view, p) = (views[v as usize], p as usize);
            b.features
                .extend_from_slice(&view.features[p * FEATURES..(p + 1) * FEATURES]);
            b.radiance
                .extend_from_slice(&view.radiance[p * 3..p * 3 + 3]);
            b.view.push(v as i64);
            b.scale.push(view.light.scale);
        }
        b
    }

    pub fn len(&self) -> usize {
        self.view.len()
    }

    pub fn is_empty(&self) -> bool {
        self.view.is_empty()
    }

    /// Predicted radiance [B, 3] and the reference [B, 3] on `device`.
    pub fn forward(&self, net: &NprtNet, device: &Device) -> (Tensor<2>, Tensor<2>) {
        let n = self.len();
        let w = self.light_width;
        let f = Tensor::from_data(
            TensorData::new(self.features.clone(), [n, FEATURES]),
            device,
        );
        let r = Tensor::from_data(TensorData::new(self.radiance.clone(), [n, 3]), device);
        let v = Tensor::<1, Int>::from_data(TensorData::new(self.view.clone(), [n]), device);
        let s = Tensor::from_data(TensorData::new(self.scale.clone(), [n, 1]), device);
        let l = Tensor::from_data(
            TensorData::new(
                self.lights.clone(),
                [self.lights.len() / (3 * w * w / 2), 3, w / 2, w],
            ),
            device,
        );
        (net.forward(f, l, v, s), r)
    }
}

/// All pixels of a group of views, shuffled by the epoch's seed and cut into near-equal batches.
fn group_batches(views: &[&ViewSamples], count: usize, rng: &mut Pcg64Mcg) -> Vec<Vec<(u32, u32)>> {
    let mut all: Vec<(u32, u32)> = views
        .iter()
        .enumerate()
        .flat_map(|(v, s)| (0..s.len() as u32).map(move |p| (v as u32, p)))
        .collect();
    all.shuffle(rng);
    let n = all.len();
    (0..count)
        .map(|i| all[i * n / count..(i + 1) * n / count].to_vec())
        .collect()
}

/// Mean log-L1 loss over a fixed, evenly strided subset of the test views' pixels.
pub fn validation_loss(
    net: &NprtNet,
    set: &TrainingSet,
    opts: &TrainOptions,
    device: &Device,
) -> f64 {
    let views: Vec<&ViewSamples> = set.test.iter().filter(|v| !v.is_empty()).collect();
    let total: usize = views.iter().map(|v| v.len()).sum();
    if total == 0 {
        return f64::NAN;
    }
    let stride = total.div_ceil(opts.val_samples.max(1));
    let mut picked = Vec::new();
    let mut k = 0;
    for (v, view) in views.iter().enumerate() {
        for p in 0..view.len() {
            if k % stride == 0 {
                picked.push((v as u32, p as u32));
            }
            k += 1;
        }
    }
    let mut sum = 0.0;
    for chunk in picked.chunks(opts.batch_size) {
        // Only the views this chunk touches go through the encoder.
        let mut used: Vec<u32> = chunk.iter().map(|s| s.0).collect();
        used.dedup();
        let local: Vec<(u32, u32)> = chunk
            .iter()
            .map(|&(v, p)| (used.binary_search(&v).unwrap() as u32, p))
            .collect();
        let sub: Vec<&ViewSamples> = used.iter().map(|&v| views[v as usize]).collect();
        let batch = Batch::gather(&sub, &local);
        let (pred, reference) = batch.forward(net, device);
        let loss = log_l1(pred, reference).into_scalar::<f32>() as f64;
        sum += loss * chunk.len() as f64;
    }
    sum / picked.len() as f64
}

fn checkpoint_dir(out: &Path) -> PathBuf {
    out.join(CHECKPOINT_DIR)
}

fn read_checkpoint(out: &Path) -> Result<Option<Checkpoint>> {
    let path = checkpoint_dir(out).join(STATE_FILE);
    if !path.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read checkpoint '{}'", path.display()))?;
    let ck = serde_json::from_str(&text)
        .with_context(|| format!("checkpoint '{}' is malformed", path.display()))?;
    Ok(Some(ck))
}

/// Trains (or resumes training of) the model in `out`.
pub fn train(
    set: &TrainingSet,
    config: &ModelConfig,
    opts: &TrainOptions,
    out: &Path,
    device: &Device,
) -> Result<TrainSummary> {
    let device = device.clone().autodiff();
    let mut net = config.build(&mut Init::new(opts.seed, &device));
    let mut optim = AdamConfig::new().with_epsilon(1e-8).init();
    std::fs::create_dir_all(checkpoint_dir(out))
        .with_context(|| format!("cannot create model folder '{}'", out.display()))?;

    let mut ck = Checkpoint {
        config: config.clone(),
        options: opts.clone(),
        dataset_hash: set.dataset_hash.clone(),
        epoch: 0,
        batch: 0,
        step: 0,
        samples: 0,
        seconds: 0.0,
        history: Vec::new(),
        weights: String::new(),
        optimizer: String::new(),
    };
    let mut resumed_from_epoch = None;
    if let Some(saved) = read_checkpoint(out)? {
        let same_run = saved.config == ck.config
            && saved.dataset_hash == ck.dataset_hash
            && saved.options.same_run(&ck.options);
        if !same_run {
            bail!(
                "model folder '{}' holds a run with other settings (design, activation, dataset or hyper-parameters); choose another --out or delete it",
                out.display()
            );
        }
        let dir = checkpoint_dir(out);
        load_weights(&dir.join(&saved.weights), &mut net, config.design.name())?;
        optim = optim.load(dir.join(&saved.optimizer)).map_err(|e| {
            anyhow::anyhow!("cannot read optimiser state in '{}': {e:?}", dir.display())
        })?;
        let plan = EpochPlan::new(set, opts, saved.epoch);
        let at = saved.epoch as f64 + saved.batch as f64 / plan.total().max(1) as f64;
        if opts.progress {
            eprintln!("resuming '{}' from epoch {at:.2}", out.display());
        }
        resumed_from_epoch = Some(at);
        ck = Checkpoint {
            options: opts.clone(),
            ..saved
        };
    }

    let per_epoch: Vec<usize> = (0..opts.epochs)
        .map(|e| EpochPlan::new(set, opts, e).total())
        .collect();
    let total_batches: usize = per_epoch.iter().sum();
    let done_batches: usize = per_epoch.iter().take(ck.epoch).sum::<usize>() + ck.batch;
    let bar = nprt_io::progress_bar(opts.progress, total_batches as u64, "training", "batches");
    bar.set_position(done_batches as u64);
    bar.reset_eta();
    let started = Instant::now();
    let seconds_before = ck.seconds;
    let mut last_checkpoint = Instant::now();
    let (mut row_sum, mut row_n) = (0.0f64, 0u64);
    let mut last_train = f64::NAN;
    let mut best_ema = f64::INFINITY;
    let mut ema = f64::NAN;

    while ck.epoch < opts.epochs {
        let plan = EpochPlan::new(set, opts, ck.epoch);
        let total = plan.total();
        let row_every = (total as u64).div_ceil(TRAIN_ROWS_PER_EPOCH).max(1);
        let mut first = 0;
        for (g, group) in plan.groups.iter().enumerate() {
            let count = plan.batches[g];
            if ck.batch >= first + count {
                first += count;
                continue;
            }
            let views: Vec<&ViewSamples> = group.iter().map(|&v| &set.train[v]).collect();
            let batches = group_batches(
                &views,
                count,
                &mut rng_for(opts.seed, ck.epoch as u64, g as u64),
            );
            for (i, samples) in batches.iter().enumerate().skip(ck.batch - first) {
                let batch = Batch::gather(&views, samples);
                let (pred, reference) = batch.forward(&net, &device);
                let loss = log_l1(pred, reference);
                let value = loss.clone().into_scalar::<f32>() as f64;
                ema = if ema.is_nan() {
                    value
                } else {
                    0.98 * ema + 0.02 * value
                };
                if ck.step > 200 {
                    best_ema = best_ema.min(ema);
                }
                if !value.is_finite() || ema > 10.0 * best_ema {
                    bar.abandon();
                    let kept = if checkpoint_dir(out).join(STATE_FILE).exists() {
                        format!(
                            "the last good checkpoint in '{}' is kept",
                            checkpoint_dir(out).display()
                        )
                    } else {
                        "no checkpoint had been written yet".to_string()
                    };
                    bail!(
                        "training diverged at epoch {} step {} (loss {value}, running mean {ema:.4}, best {best_ema:.4}); {kept}; lower --lr and use another --out",
                        ck.epoch + 1,
                        ck.step
                    );
                }
                let grads = GradientsParams::from_grads(loss.backward(), &net);
                net = optim.step(opts.learning_rate, net, grads);
                ck.batch = first + i + 1;
                ck.step += 1;
                ck.samples += batch.len() as u64;
                row_sum += value;
                row_n += 1;
                last_train = value;
                let elapsed = started.elapsed().as_secs_f64();
                ck.seconds = seconds_before + elapsed;
                if ck.step.is_multiple_of(row_every) {
                    ck.history.push(LossRow {
                        step: ck.step,
                        epoch: ck.epoch as f64 + ck.batch as f64 / total as f64,
                        samples: ck.samples,
                        seconds: ck.seconds,
                        train: Some(row_sum / row_n as f64),
                        val: None,
                    });
                    (row_sum, row_n) = (0.0, 0);
                }
                bar.inc(1);
                bar.set_message(format!(
                    "epoch {}/{} loss {ema:.4} {:.0}K samples/s",
                    ck.epoch + 1,
                    opts.epochs,
                    ck.samples as f64 / ck.seconds.max(1e-9) / 1e3
                ));
                if last_checkpoint.elapsed().as_secs_f64() > opts.checkpoint_secs {
                    write_checkpoint(out, &mut ck, &net, &optim, set)?;
                    last_checkpoint = Instant::now();
                }
            }
            first += count;
        }
        let val = validation_loss(&net.valid(), set, opts, &device.clone().inner());
        ck.epoch += 1;
        ck.batch = 0;
        ck.history.push(LossRow {
            step: ck.step,
            epoch: ck.epoch as f64,
            samples: ck.samples,
            seconds: ck.seconds,
            train: (row_n > 0).then(|| row_sum / row_n as f64),
            val: Some(val),
        });
        (row_sum, row_n) = (0.0, 0);
        if opts.progress {
            // Also when the bar is hidden (output not a terminal), so logs show progress.
            bar.suspend(|| {
                eprintln!(
                    "epoch {:>4}/{}: train loss {:.5}, validation loss {val:.5}, {:.0} K samples/s",
                    ck.epoch,
                    opts.epochs,
                    ck.history
                        .iter()
                        .rev()
                        .find_map(|r| r.train)
                        .unwrap_or(last_train),
                    ck.samples as f64 / ck.seconds.max(1e-9) / 1e3
                )
            });
        }
        write_checkpoint(out, &mut ck, &net, &optim, set)?;
        last_checkpoint = Instant::now();
    }
    bar.finish_and_clear();
    let final_val = ck
        .history
        .iter()
        .rev()
        .find_map(|r| r.val)
        .unwrap_or(f64::NAN);
    let final_train = ck
        .history
        .iter()
        .rev()
        .find_map(|r| r.train)
        .unwrap_or(last_train);
    Ok(TrainSummary {
        steps: ck.step,
        samples: ck.samples,
        seconds: ck.seconds,
        final_train,
        final_val,
        resumed_from_epoch,
    })
}

/// Weights, optimiser state, then the state file that names them; then the model folder's own
/// weights, config, CSV and plot. Older checkpoint files are removed last.
fn write_checkpoint(
    out: &Path,
    ck: &mut Checkpoint,
    net: &NprtNet,
    optim: &ModuleOptimizer,
    set: &TrainingSet,
) -> Result<()> {
    let dir = checkpoint_dir(out);
    let weights = format!("weights-{:09}.safetensors", ck.step);
    let optimizer = format!("optimizer-{:09}.bpk", ck.step);
    save_weights(&dir.join(&weights), net, ck.config.design.name())?;
    optim
        .save(dir.join(&optimizer))
        .map_err(|e| anyhow::anyhow!("cannot write optimiser state: {e:?}"))?;
    ck.weights = weights;
    ck.optimizer = optimizer;
    let json = serde_json::to_vec_pretty(ck)?;
    nprt_io::write_file(&dir.join(STATE_FILE), &json)?;
    for entry in std::fs::read_dir(&dir)?.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        if (name.starts_with("weights-") || name.starts_with("optimizer-"))
            && name != ck.weights
            && name != ck.optimizer
        {
            std::fs::remove_file(entry.path()).ok();
        }
    }

    let transport_params = net.transport_params();
    let file = ModelFile {
        format: MODEL_FORMAT.into(),
        version: MODEL_VERSION,
        config: ck.config.clone(),
        bounds: set.manifest.bounds,
        scene: set.manifest.settings.scene.clone(),
        scene_hash: set.manifest.settings.scene_hash.clone(),
        dataset_hash: set.dataset_hash.clone(),
        transport_params,
        encoder_params: net.num_params() - transport_params,
        training: serde_json::json!({
            "options": ck.options,
            "epochs_done": ck.epoch,
            "steps": ck.step,
            "samples": ck.samples,
            "seconds": ck.seconds,
            "adam_epsilon": 1e-8,
            "loss": "mean |log(1 + prediction) − log(1 + reference)|",
        }),
    };
    save_model(out, &file, net)?;
    crate::curves::write_csv(&out.join("loss.csv"), &ck.history)?;
    crate::curves::plot(
        &out.join("loss.png"),
        &ck.history,
        &format!(
            "{} ({})",
            ck.config.design.name(),
            ck.config.activation.name()
        ),
    )
}

/// Training throughput in samples/s: `steps` full steps (forward, backward, Adam) on one
/// synthetic batch of `batch_size` samples over `views` maps, after `warmup` untimed steps.
pub fn measure_throughput(
    config: &ModelConfig,
    batch_size: usize,
    views: usize,
    steps: usize,
    warmup: usize,
    device: &Device,
) -> f64 {
    use rand::RngExt;
    let device = device.clone().autodiff();
    let mut net = config.build(&mut Init::new(0, &device));
    let mut optim = AdamConfig::new().with_epsilon(1e-8).init();
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let w = config.encoder_width;
    let mut random = |n: usize, scale: f32| -> Vec<f32> {
        (0..n).map(|_| rng.random::<f32>() * scale).collect()
    };
    let batch = Batch {
        features: random(batch_size * FEATURES, 1.0),
        radiance: random(batch_size * 3, 4.0),
        view: (0..batch_size).map(|i| (i % views) as i64).collect(),
        scale: random(batch_size, 1.0)
            .into_iter()
            .map(|s| s + 0.5)
            .collect(),
        lights: random(views * 3 * w * w / 2, 1.0),
        light_width: w,
    };
    let mut timed = Instant::now();
    for step in 0..warmup + steps {
        if step == warmup {
            device.sync().ok();
            timed = Instant::now();
        }
        let (pred, reference) = batch.forward(&net, &device);
        let grads = GradientsParams::from_grads(log_l1(pred, reference).backward(), &net);
        net = optim.step(1e-4, net, grads);
    }
    device.sync().ok();
    (batch_size * steps) as f64 / timed.elapsed().as_secs_f64()
}
