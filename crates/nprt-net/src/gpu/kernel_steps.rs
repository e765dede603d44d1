//! Training steps of a Neural PRT design on our own GPU kernels, as the training loop takes
//! them ([`DeviceSteps`]): the parameters and Adam's moments stay on the device between steps
//! and come back to the host network only for validation and checkpoints.

use std::path::Path;

use anyhow::Result;

use super::GpuTrainer;
use crate::network::nprt_net::NprtNet;
use crate::training::batch::Batch;
use crate::training::loss::Loss;
use crate::training::optimiser::DeviceSteps;

pub struct KernelSteps {
    trainer: GpuTrainer,
    loss: Loss,
}

impl KernelSteps {
    /// Uploads `net`'s weights; steps minimise `loss`.
    pub fn new(net: &NprtNet, loss: Loss) -> Result<Self> {
        Ok(KernelSteps {
            trainer: GpuTrainer::new(net)?,
            loss,
        })
    }
}

impl DeviceSteps<NprtNet, Batch> for KernelSteps {
    fn step(&mut self, batch: &Batch, lr: f64) -> Result<(f64, u64)> {
        let loss = self.trainer.step(&batch.samples(), self.loss, lr);
        Ok((loss, batch.len() as u64))
    }

    fn store(&self, net: &mut NprtNet) {
        let (encoder, transport) = self.trainer.parameters();
        encoder.store_into(&mut net.encoder);
        transport.store_into(net);
    }

    fn save(&self, path: &Path) -> Result<()> {
        self.trainer.save_state(path)
    }

    fn load(&mut self, path: &Path) -> Result<()> {
        self.trainer.load_state(path)
    }

    fn describe(&self) -> String {
        format!("GPU kernels on {}", self.trainer.adapter())
    }
}
