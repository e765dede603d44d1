//! Training steps of a Neural PRT design on our own GPU kernels, as the training loop takes
//! them ([`EngineSteps`]): the parameters and Adam's moments stay on the device between steps
//! and come back to the host network only for checkpoints (validation runs on the device too),
//! and the dataset may be held there as well.

use std::path::Path;

use anyhow::Result;

use crate::gpu::{DeviceDataset, GpuTrainer};
use crate::loss::Loss;
use crate::network::nprt_net::NprtNet;
use crate::optimiser::EngineSteps;
use crate::precision::Precision;
use crate::training::batch::Batch;
use crate::training::training_set::TrainingSet;

pub struct KernelSteps {
    trainer: GpuTrainer,
    loss: Loss,
    /// Samples of the queued steps whose losses are not yet read (at most two).
    samples: std::collections::VecDeque<u64>,
    /// Bytes of the dataset held on the device, where it is.
    resident: Option<u64>,
}

impl KernelSteps {
    /// Uploads `net`'s weights, and `dataset` where given (steps then take picked batches,
    /// [`Batch::picked`]); steps minimise `loss` in `precision`.
    pub fn new(
        net: &NprtNet,
        loss: Loss,
        precision: Precision,
        dataset: Option<&TrainingSet>,
    ) -> Result<Self> {
        let mut trainer = GpuTrainer::new(net, precision)?;
        let mut resident = None;
        if let Some(set) = dataset {
            let maps: Vec<_> = set.train.iter().map(|v| &v.light).collect();
            let data = DeviceDataset::upload(trainer.gpu(), &set.pack, &maps)?;
            resident = Some(data.bytes);
            trainer.hold(data);
        }
        Ok(KernelSteps {
            trainer,
            loss,
            samples: Default::default(),
            resident,
        })
    }
}

impl EngineSteps<NprtNet, Batch> for KernelSteps {
    fn step(&mut self, batch: &Batch, lr: f64) -> Result<Option<(f64, u64)>> {
        self.samples.push_back(batch.len() as u64);
        let before = match &batch.picks {
            Some(p) => self.trainer.queue_picked_step(
                &p.records,
                &p.views,
                batch.light_width,
                self.loss,
                lr,
            ),
            None => self.trainer.queue_step(&batch.samples(), self.loss, lr),
        };
        Ok(before.map(|loss| (loss, self.samples.pop_front().expect("queued"))))
    }

    fn finish(&mut self) -> Result<Option<(f64, u64)>> {
        let last = self.trainer.finish();
        Ok(last.map(|loss| (loss, self.samples.pop_front().expect("queued"))))
    }

    fn loss(&mut self, batch: &Batch) -> Result<f64> {
        Ok(self.trainer.loss(&batch.samples(), Loss::LogL1))
    }

    fn store(&self, net: &mut NprtNet) {
        *net = self.trainer.parameters();
    }

    fn save(&self, path: &Path) -> Result<()> {
        self.trainer.save_state(path)
    }

    fn load(&mut self, path: &Path) -> Result<()> {
        self.trainer.load_state(path)
    }

    fn describe(&self) -> String {
        let data = match self.resident {
            Some(bytes) => format!("the dataset there ({:.1} MB)", bytes as f64 / 1e6),
            None => "batches gathered here".into(),
        };
        let products = match (self.trainer.precision(), self.trainer.gpu().tensor_cores) {
            (Precision::F32, _) => "",
            (Precision::F16, true) => ", mixed precision on tensor cores",
            (Precision::F16, false) => {
                ", mixed precision without tensor cores (the adapter has no cooperative matrices)"
            }
        };
        format!(
            "GPU kernels on {}{products}, {data}",
            self.trainer.adapter()
        )
    }
}
