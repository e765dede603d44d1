//! Training steps on the CPU engine, as the training loop takes them ([`EngineSteps`]): the
//! objective's gradients of the network, then [`Adam`] on the host, one step at a time.

use std::path::Path;

use anyhow::Result;

use crate::optimiser::{Adam, EngineSteps};
use crate::parameters::Parameters;

/// A batch's mean loss, the network's gradient (same shapes) and its samples.
type Gradients<'a, N, B> = dyn Fn(&N, &B) -> (f64, N, u64) + 'a;
/// A batch's mean validation loss.
type BatchLoss<'a, N, B> = dyn Fn(&N, &B) -> f64 + 'a;

/// The network being trained, Adam's state, and how the objective's loss and gradients are
/// computed on the CPU engine (closures that may borrow the objective's data).
pub struct HostSteps<'a, N, B> {
    net: N,
    adam: Adam,
    gradients: Box<Gradients<'a, N, B>>,
    loss: Box<BatchLoss<'a, N, B>>,
}

impl<'a, N: Parameters + Clone, B> HostSteps<'a, N, B> {
    /// Steps from `net`'s weights as they stand, with fresh moments.
    pub fn new(
        net: &N,
        gradients: impl Fn(&N, &B) -> (f64, N, u64) + 'a,
        loss: impl Fn(&N, &B) -> f64 + 'a,
    ) -> Self {
        HostSteps {
            adam: Adam::new(net.num_params()),
            net: net.clone(),
            gradients: Box::new(gradients),
            loss: Box::new(loss),
        }
    }
}

impl<N: Parameters + Clone, B> EngineSteps<N, B> for HostSteps<'_, N, B> {
    fn step(&mut self, batch: &B, lr: f64) -> Result<Option<(f64, u64)>> {
        let (loss, grads, samples) = (self.gradients)(&self.net, batch);
        self.adam.step(&mut self.net, &grads, lr);
        Ok(Some((loss, samples)))
    }

    fn finish(&mut self) -> Result<Option<(f64, u64)>> {
        Ok(None)
    }

    fn loss(&mut self, batch: &B) -> Result<f64> {
        Ok((self.loss)(&self.net, batch))
    }

    fn store(&self, net: &mut N) {
        net.clone_from(&self.net);
    }

    fn save(&self, path: &Path) -> Result<()> {
        self.adam.save(path)
    }

    fn load(&mut self, path: &Path) -> Result<()> {
        self.adam.load(path)
    }

    fn describe(&self) -> String {
        "cpu".into()
    }
}
