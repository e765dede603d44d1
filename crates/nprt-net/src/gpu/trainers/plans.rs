//! What the device trainers (a design's, the U-Net's, the radiance cache's) keep between calls:
//! the passes recorded for the batch shapes asked for last, and what a submission of one runs.

use crate::gpu::passes::device_adam::DeviceAdam;
use nprt_gpu::{Dispatch, GpuDevice};

/// Batch shapes whose passes are kept: training's and validation's, and each epoch's shorter
/// last batch (or a read's and a training step's, and their shorter last ones).
const KEPT: usize = 4;

/// Passes recorded for the shapes used last, the most recent last.
pub struct Plans<P>(Vec<P>);

impl<P> Default for Plans<P> {
    fn default() -> Self {
        Plans(Vec::new())
    }
}

impl<P> Plans<P> {
    /// The kept pass `fits` finds, taken out to be kept again as the most recent
    /// ([`Self::keep`]); when none fits, room is made for the one the caller will record (the
    /// oldest dropped when [`KEPT`] are kept).
    pub fn take(&mut self, fits: impl Fn(&P) -> bool) -> Option<P> {
        match self.0.iter().position(fits) {
            Some(i) => Some(self.0.remove(i)),
            None => {
                if self.0.len() == KEPT {
                    self.0.remove(0);
                }
                None
            }
        }
    }

    /// Keeps `plan` as the most recent.
    pub fn keep(&mut self, plan: P) {
        self.0.push(plan);
    }

    /// The pass used last.
    pub fn last(&self) -> Option<&P> {
        self.0.last()
    }

    pub fn clear(&mut self) {
        self.0.clear();
    }
}

/// What a submission of a recorded pass runs.
#[derive(Clone, Copy)]
pub enum Pass {
    /// The loss alone (the forward part).
    Forward,
    /// The loss and every gradient.
    Backward,
    /// The loss, every gradient and Adam at this learning rate.
    Step(f64),
}

impl Pass {
    /// The dispatches of a recorded pass this runs: the first `forward` of them, or all.
    pub fn of(self, dispatches: &[Dispatch], forward: usize) -> &[Dispatch] {
        match self {
            Pass::Forward => &dispatches[..forward],
            _ => dispatches,
        }
    }

    /// Adam's learning rate, where this takes a step.
    pub fn learning_rate(self) -> Option<f64> {
        match self {
            Pass::Step(lr) => Some(lr),
            _ => None,
        }
    }
}

/// Submits what `pass` runs of a recorded pass (`dispatches`, the first `forward` its forward
/// part) in one compute pass, with `adam`'s step over `total` values after them where `pass`
/// steps (gradients unscaled); the caller reads what it needs back.
pub fn submit(
    gpu: &GpuDevice,
    (dispatches, forward): (&[Dispatch], usize),
    pass: Pass,
    (adam, total): (&mut DeviceAdam, usize),
) {
    let step = pass.learning_rate().map(|lr| {
        adam.next_step(gpu, total, lr, 1.0);
        &adam.dispatch
    });
    gpu.submit(pass.of(dispatches, forward).iter().chain(step));
}
