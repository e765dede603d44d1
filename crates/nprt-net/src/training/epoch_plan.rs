//! Which pixels make each batch of an epoch: views are shuffled into groups (of
//! `views_per_batch`), and each group's pixels are shuffled and cut into near-equal batches.
//! Everything is a function of the seed and the epoch, so a resumed run sees the same batches.

use rand::seq::SliceRandom;

use crate::training::train_options::TrainOptions;
use crate::training::training_loop::epoch_rng;
use crate::training::training_set::{TrainingSet, ViewSamples};

/// How the views of one epoch are grouped and how many batches each group gives.
pub(crate) struct EpochPlan {
    pub groups: Vec<Vec<usize>>,
    pub batches: Vec<usize>,
}

impl EpochPlan {
    pub fn new(set: &TrainingSet, opts: &TrainOptions, seed: u64, epoch: usize) -> Self {
        let mut order: Vec<usize> = (0..set.train.len())
            .filter(|&v| !set.train[v].is_empty())
            .collect();
        order.shuffle(&mut epoch_rng(seed, epoch as u64, u64::MAX));
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

    pub fn total(&self) -> usize {
        self.batches.iter().sum()
    }
}

/// All pixels of a group of views as (position in `views`, pixel) pairs, shuffled by the
/// group's stream of the epoch and cut into `count` near-equal batches.
pub(crate) fn group_batches(
    views: &[&ViewSamples],
    count: usize,
    seed: u64,
    epoch: usize,
    group: usize,
) -> Vec<Vec<(u32, u32)>> {
    let mut all: Vec<(u32, u32)> = views
        .iter()
        .enumerate()
        .flat_map(|(v, s)| (0..s.len() as u32).map(move |p| (v as u32, p)))
        .collect();
    all.shuffle(&mut epoch_rng(seed, epoch as u64, group as u64));
    let n = all.len();
    (0..count)
        .map(|i| all[i * n / count..(i + 1) * n / count].to_vec())
        .collect()
}
