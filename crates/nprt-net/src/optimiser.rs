//! What updates a network's weights during training: burn's Adam over the network's own
//! tensors, or an engine of the objective's own that keeps the parameters and Adam's moments
//! on its device and takes whole steps there (nprt-net's GPU kernels). The loop and the
//! checkpoint see only this; a checkpoint's optimiser file says which of the two wrote it.

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use burn::module::Module;
use burn::optim::{AdamConfig, ModuleOptimizer};

/// Adam's ε, on every engine.
pub const ADAM_EPSILON: f32 = 1e-8;

/// Steps taken on a device of their own: the parameters and Adam's moments live there, and a
/// step is the batch's loss, gradients and Adam update together.
pub trait DeviceSteps<N, B> {
    /// Queues one step on `batch` at learning rate `lr`. Returns the step queued before it
    /// (None for the first): its batch's mean loss and its samples, read while this one runs.
    fn step(&mut self, batch: &B, lr: f64) -> Result<Option<(f64, u64)>>;
    /// The last queued step's loss and samples once it is done (None when none is pending).
    fn finish(&mut self) -> Result<Option<(f64, u64)>>;
    /// `batch`'s mean log-L1 loss under the current parameters, without a step (validation).
    fn loss(&mut self, batch: &B) -> Result<f64>;
    /// Writes the current parameters into `net` (for saving).
    fn store(&self, net: &mut N);
    /// Writes Adam's state (moments and step count) to `path`.
    fn save(&self, path: &Path) -> Result<()>;
    /// Reads Adam's state back from `path`, written by [`Self::save`] for the same network.
    fn load(&mut self, path: &Path) -> Result<()>;
    /// Where the steps run, for reports ("GPU kernels on …").
    fn describe(&self) -> String;
}

/// Burn's Adam, or a device's own steps.
pub enum Optimiser<N, B> {
    Burn(ModuleOptimizer),
    Device(Box<dyn DeviceSteps<N, B>>),
}

/// File names of the two kinds of optimiser state.
const BURN_PREFIX: &str = "optimizer-";
const DEVICE_PREFIX: &str = "adam-";

impl<N: Module, B> Optimiser<N, B> {
    /// Burn's Adam as the paper configures it (ε = 1e-8).
    pub fn burn() -> Self {
        Optimiser::Burn(AdamConfig::new().with_epsilon(ADAM_EPSILON).init())
    }

    /// Whether a checkpoint file is optimiser state.
    pub fn is_state_file(name: &str) -> bool {
        name.starts_with(BURN_PREFIX) || name.starts_with(DEVICE_PREFIX)
    }

    /// The name of this optimiser's state file at `step`.
    pub fn state_file(&self, step: u64) -> String {
        match self {
            Optimiser::Burn(_) => format!("{BURN_PREFIX}{step:09}.bpk"),
            Optimiser::Device(_) => format!("{DEVICE_PREFIX}{step:09}.safetensors"),
        }
    }

    /// The device's own steps, if they are what this optimiser is.
    pub fn device_steps(&mut self) -> Option<&mut dyn DeviceSteps<N, B>> {
        match self {
            Optimiser::Device(d) => Some(d.as_mut()),
            Optimiser::Burn(_) => None,
        }
    }

    /// Brings `net` up to date with the parameters the optimiser holds, if it holds them.
    pub fn store(&self, net: &mut N) {
        if let Optimiser::Device(d) = self {
            d.store(net);
        }
    }

    pub fn save(&self, path: &Path) -> Result<()> {
        match self {
            Optimiser::Burn(optim) => optim
                .save(path)
                .map_err(|e| anyhow!("cannot write optimiser state '{}': {e:?}", path.display())),
            Optimiser::Device(d) => d.save(path),
        }
    }

    /// Reads the state in `path`; refuses state written by the other kind, naming it.
    pub fn load(self, path: &Path) -> Result<Self> {
        let name = path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let mine = match &self {
            Optimiser::Burn(_) => name.starts_with(BURN_PREFIX),
            Optimiser::Device(_) => name.starts_with(DEVICE_PREFIX),
        };
        if !mine {
            bail!(
                "checkpoint '{}' holds Adam's state of {}; resume it with the --device that wrote it, or start over in another --out",
                path.display(),
                if name.starts_with(DEVICE_PREFIX) {
                    "nprt's own GPU kernels (--device gpu or wgpu)"
                } else {
                    "the CPU engine (--device cpu)"
                }
            );
        }
        match self {
            Optimiser::Burn(optim) => optim
                .load(path)
                .map(Optimiser::Burn)
                .map_err(|e| anyhow!("cannot read optimiser state '{}': {e:?}", path.display())),
            Optimiser::Device(mut d) => {
                d.load(path)?;
                Ok(Optimiser::Device(d))
            }
        }
    }
}
