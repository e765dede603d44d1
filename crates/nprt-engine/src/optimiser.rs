//! What trains a network's weights: an engine's steps ([`EngineSteps`]: the batch's loss,
//! gradients and an Adam update together, wherever the parameters live), and Adam on the host
//! ([`Adam`]), the update the CPU engine's steps take. nprt-net's GPU kernels run the same
//! update (`shaders/optimiser/adam.wgsl`), and both keep Adam's state in one file format, so a
//! checkpoint resumes on either engine.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use safetensors::{tensor::TensorView, Dtype, SafeTensors};

use crate::parameters::Parameters;

/// Adam's ε, on every engine.
pub const ADAM_EPSILON: f32 = 1e-8;
/// Adam's decay rates (Kingma and Ba's, and PyTorch's defaults).
pub const ADAM_BETA1: f32 = 0.9;
pub const ADAM_BETA2: f32 = 0.999;

/// Checkpoint files of Adam's state start with this.
pub const STATE_PREFIX: &str = "adam-";
/// burn's optimiser state, written by nprt before its own Adam: refused by name.
const BURN_PREFIX: &str = "optimizer-";

/// Steps on an engine: the parameters and Adam's moments live there, and a step is the
/// batch's loss, gradients and Adam update together.
pub trait EngineSteps<N, B> {
    /// Takes (or queues) one step on `batch` at learning rate `lr`. Returns a finished step's
    /// mean loss and samples: this one's on an engine that steps at once, the one queued
    /// before it on a device that runs while the host goes on (None for its first).
    fn step(&mut self, batch: &B, lr: f64) -> Result<Option<(f64, u64)>>;
    /// The last queued step's loss and samples once it is done (None when none is pending).
    fn finish(&mut self) -> Result<Option<(f64, u64)>>;
    /// `batch`'s mean log-L1 loss under the current parameters, without a step (validation).
    fn loss(&mut self, batch: &B) -> Result<f64>;
    /// Writes the current parameters into `net` (for saving).
    fn store(&self, net: &mut N);
    /// Writes Adam's state (moments and step count) to `path`.
    fn save(&self, path: &Path) -> Result<()>;
    /// Reads Adam's state back from `path`, written by [`Self::save`] on any engine for a
    /// network of the same shapes.
    fn load(&mut self, path: &Path) -> Result<()>;
    /// Where the steps run, for reports ("cpu", "GPU kernels on …").
    fn describe(&self) -> String;
}

/// Whether a checkpoint file is optimiser state (this nprt's or burn's, to clean up).
pub fn is_state_file(name: &str) -> bool {
    name.starts_with(STATE_PREFIX) || name.starts_with(BURN_PREFIX)
}

/// The name of Adam's state file at `step`.
pub fn state_file(step: u64) -> String {
    format!("{STATE_PREFIX}{step:09}.safetensors")
}

/// Adam's state over a network's parameters, flat in their visiting order.
pub struct Adam {
    moment1: Vec<f32>,
    moment2: Vec<f32>,
    steps: u64,
    /// β1 and β2.
    betas: [f32; 2],
}

impl Adam {
    /// Zero moments for `params` values.
    pub fn new(params: usize) -> Self {
        Self::with_betas(params, [ADAM_BETA1, ADAM_BETA2])
    }

    /// Zero moments for `params` values, with decay rates of one's own (the radiance cache's
    /// faster second moment, which follows a target that moves as it trains).
    pub fn with_betas(params: usize, betas: [f32; 2]) -> Self {
        Adam {
            moment1: vec![0.0; params],
            moment2: vec![0.0; params],
            steps: 0,
            betas,
        }
    }

    /// One update of `net` by its gradient `grads` (same shapes) at learning rate `lr`:
    /// m ← β1 m + (1 − β1) g, v ← β2 v + (1 − β2) g², θ ← θ − lr · (m · c) / (√v + ε · √(1 − β2^t))
    /// with c = √(1 − β2^t) / (1 − β1^t), in this order in f32 (burn's formulation, which
    /// trained nprt's models before, and the GPU kernels').
    pub fn step<N: Parameters>(&mut self, net: &mut N, grads: &N, lr: f64) {
        self.steps += 1;
        let [beta1, beta2] = self.betas;
        let (factor, epsilon) = bias_corrections_for(self.steps, self.betas);
        let lr = lr as f32;
        let g = grads.flat();
        let (m, v) = (&mut self.moment1, &mut self.moment2);
        let mut at = 0;
        net.visit_mut("", &mut |_, _, w| {
            let range = at..at + w.len();
            at = range.end;
            let moments = m[range.clone()].iter_mut().zip(&mut v[range.clone()]);
            for ((w, g), (m, v)) in w.iter_mut().zip(&g[range]).zip(moments) {
                *m = *m * beta1 + *g * (1.0 - beta1);
                *v = *v * beta2 + (*g * *g) * (1.0 - beta2);
                *w -= (*m * factor) / (v.sqrt() + epsilon) * lr;
            }
        });
        assert_eq!(at, m.len(), "gradients of the network Adam was made for");
    }

    pub fn save(&self, path: &Path) -> Result<()> {
        save_state(path, [&self.moment1, &self.moment2], self.steps)
    }

    pub fn load(&mut self, path: &Path) -> Result<()> {
        let ([m1, m2], steps) = load_state(path, self.moment1.len())?;
        (self.moment1, self.moment2, self.steps) = (m1, m2, steps);
        Ok(())
    }
}

/// Step `t`'s (from 1) bias corrections, as every engine's update takes them: the factor
/// c = √(1 − β2^t) / (1 − β1^t) on the first moment, and ε · √(1 − β2^t).
pub fn bias_corrections(t: u64) -> (f32, f32) {
    bias_corrections_for(t, [ADAM_BETA1, ADAM_BETA2])
}

/// [`bias_corrections`] under decay rates `[β1, β2]`.
pub fn bias_corrections_for(t: u64, [beta1, beta2]: [f32; 2]) -> (f32, f32) {
    let t = t.min(i32::MAX as u64) as i32;
    let c2 = (1.0 - beta2.powi(t)).sqrt();
    (c2 / (1.0 - beta1.powi(t)), ADAM_EPSILON * c2)
}

/// Writes Adam's two moments (flat, in visiting order) and its step count to `path`.
pub fn save_state(path: &Path, moments: [&[f32]; 2], steps: u64) -> Result<()> {
    let views = ["moment1", "moment2"]
        .into_iter()
        .zip(moments)
        .map(|(name, m)| {
            let bytes: &[u8] = bytemuck::cast_slice(m);
            Ok((name, TensorView::new(Dtype::F32, vec![m.len()], bytes)?))
        })
        .collect::<Result<Vec<_>, safetensors::SafeTensorError>>()?;
    let metadata = HashMap::from([("steps".to_string(), steps.to_string())]);
    let file = safetensors::serialize(views, Some(metadata))?;
    nprt_io::write_file(path, &file)
}

/// Reads what [`save_state`] wrote for a network of `params` values; refuses burn's optimiser
/// state by name.
pub fn load_state(path: &Path, params: usize) -> Result<([Vec<f32>; 2], u64)> {
    let name = path
        .file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned());
    if name.starts_with(BURN_PREFIX) {
        bail!(
            "checkpoint '{}' holds burn's Adam state, written by an nprt before its own Adam, which this nprt cannot read; finish the run with the nprt that started it, or delete '{}' to start over",
            path.display(),
            path.parent().map_or(path, |p| p).display()
        );
    }
    let bytes = nprt_io::read_input(path)
        .with_context(|| format!("cannot read Adam's state '{}'", path.display()))?;
    let bad = |why: String| anyhow!("Adam's state '{}' {why}", path.display());
    let file = SafeTensors::deserialize(&bytes).map_err(|e| bad(format!("is unreadable: {e}")))?;
    let (_, metadata) = SafeTensors::read_metadata(&bytes).map_err(|e| bad(e.to_string()))?;
    let steps = metadata
        .metadata()
        .as_ref()
        .and_then(|m| m.get("steps"))
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| bad("has no step count".into()))?;
    let moment = |name: &str| -> Result<Vec<f32>> {
        let view = file
            .tensor(name)
            .map_err(|e| bad(format!("lacks {name}: {e}")))?;
        if view.dtype() != Dtype::F32 || view.shape() != [params] {
            return Err(bad(format!(
                "holds {name} of {:?} {:?}, not this network's {params} f32",
                view.dtype(),
                view.shape(),
            )));
        }
        Ok(view
            .data()
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect())
    };
    Ok(([moment("moment1")?, moment("moment2")?], steps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layers::dense::Dense;

    fn layer(values: [f32; 3]) -> Dense {
        Dense {
            weight: values[..2].to_vec(),
            bias: values[2..].to_vec(),
            d_in: 1,
            d_out: 2,
        }
    }

    /// Under a constant gradient Adam's bias-corrected update is g / (|g| + ε) every step:
    /// each weight moves by the rate against its gradient's sign, whatever its size.
    #[test]
    fn a_constant_gradient_moves_each_weight_by_the_rate() {
        let mut net = layer([1.0, -2.0, 0.5]);
        let grads = layer([3e-3, -40.0, 0.25]);
        let mut adam = Adam::new(3);
        for step in 1..=3 {
            adam.step(&mut net, &grads, 0.01);
            let want = [
                1.0 - 0.01 * step as f32,
                -2.0 + 0.01 * step as f32,
                0.5 - 0.01 * step as f32,
            ];
            for (got, want) in net.flat().iter().zip(want) {
                assert!(
                    (got - want).abs() < 1e-5,
                    "step {step}: {got} against {want}"
                );
            }
        }
    }

    /// Saved and read back, Adam's state continues to the bit.
    #[test]
    fn state_survives_a_file_round_trip() {
        let dir = std::env::temp_dir().join(format!("nprt-adam-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let grads = [layer([0.3, -0.1, 2.0]), layer([-0.2, 0.4, 1.0])];
        let (mut net, mut adam) = (layer([1.0, 2.0, 3.0]), Adam::new(3));
        adam.step(&mut net, &grads[0], 1e-3);
        let path = dir.join(state_file(1));
        adam.save(&path).unwrap();
        let mut resumed = Adam::new(3);
        resumed.load(&path).unwrap();
        let mut other = net.clone();
        adam.step(&mut net, &grads[1], 1e-3);
        resumed.step(&mut other, &grads[1], 1e-3);
        assert_eq!(net, other);
        // A network of another size is refused, naming the file.
        let err = Adam::new(4).load(&path).unwrap_err().to_string();
        assert!(err.contains("not this network's 4"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }

    /// burn's optimiser state, from checkpoints written before nprt's own Adam, is refused by
    /// name with what to do, before the file is read.
    #[test]
    fn burns_optimiser_state_is_refused_by_name() {
        let path = Path::new("/nonexistent/checkpoint/optimizer-000000006.bpk");
        let err = Adam::new(3).load(path).unwrap_err().to_string();
        assert!(
            err.contains("burn's Adam state") && err.contains("delete '/nonexistent/checkpoint'"),
            "{err}"
        );
        assert!(is_state_file("optimizer-000000006.bpk") && is_state_file(&state_file(6)));
    }
}
