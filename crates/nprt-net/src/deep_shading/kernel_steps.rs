//! Deep Shading's training steps on the GPU kernels, as the training loop takes them
//! ([`EngineSteps`]): the views batched on the host as for the CPU engine, the U-Net's
//! parameters and Adam's moments on the device between steps, back on the host only for
//! checkpoints.

use std::path::Path;

use anyhow::Result;

use super::split::Split;
use crate::gpu::GpuUnet;
use crate::loss::Loss;
use crate::network::unet::DeepShading;
use crate::optimiser::EngineSteps;

pub struct UnetKernelSteps<'a> {
    unet: GpuUnet,
    train: &'a Split,
    test: &'a Split,
}

impl<'a> UnetKernelSteps<'a> {
    /// Uploads `net`'s weights; steps take their views from `train`, validation from `test`.
    pub fn new(net: &DeepShading, train: &'a Split, test: &'a Split) -> Result<Self> {
        Ok(UnetKernelSteps {
            unet: GpuUnet::new(net)?,
            train,
            test,
        })
    }
}

impl EngineSteps<DeepShading, Vec<usize>> for UnetKernelSteps<'_> {
    fn step(&mut self, batch: &Vec<usize>, lr: f64) -> Result<Option<(f64, u64)>> {
        let (views, foreground) = self.train.batch(batch);
        let loss = self.unet.step(&views, Loss::LogL1, lr);
        Ok(Some((loss, foreground)))
    }

    fn finish(&mut self) -> Result<Option<(f64, u64)>> {
        Ok(None)
    }

    fn loss(&mut self, batch: &Vec<usize>) -> Result<f64> {
        Ok(self.unet.loss(&self.test.batch(batch).0, Loss::LogL1))
    }

    fn store(&self, net: &mut DeepShading) {
        *net = self.unet.parameters();
    }

    fn save(&self, path: &Path) -> Result<()> {
        self.unet.save_state(path)
    }

    fn load(&mut self, path: &Path) -> Result<()> {
        self.unet.load_state(path)
    }

    fn describe(&self) -> String {
        format!("GPU kernels on {}", self.unet.adapter())
    }
}
