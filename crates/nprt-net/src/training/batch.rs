//! A batch of pixel samples in host memory, or picked for a device that holds the dataset.

use crate::cpu::Samples;

use crate::encoding::features::FEATURES;
use crate::training::training_set::ViewSamples;

/// Samples drawn from several views, and those views' maps: gathered on the host, or only
/// picked, for a device that holds the dataset to gather.
pub struct Batch {
    pub features: Vec<f32>,
    pub radiance: Vec<f32>,
    /// [n, K, 3] transfer vectors, where the model learns them (else empty).
    pub transfer: Vec<f32>,
    /// Index into `lights` of each sample.
    pub view: Vec<i64>,
    /// [n, 3] what the prediction's channels are multiplied by (the map's `LightInput::scale`).
    pub scale: Vec<f32>,
    /// [V, 3, W/2, W] pre-processed maps.
    pub lights: Vec<f32>,
    /// W of the maps.
    pub light_width: usize,
    /// What a device holding the dataset gathers (the host's inputs above are then empty).
    pub picks: Option<Picks>,
}

/// A batch's samples by where they lie in the dataset.
pub struct Picks {
    /// Per sample: its record's index in the pack, and its view within the batch.
    pub records: Vec<u32>,
    /// Per view of the batch: its index among the training views.
    pub views: Vec<u32>,
}

impl Batch {
    /// Refuses a batch of `samples` samples over `views` maps `light_width` wide (0: maps not
    /// counted) that the machine's memory cannot hold: its inputs, targets, scales and view
    /// indices, and the maps, before any is allocated.
    pub fn check_size(samples: usize, views: usize, light_width: usize) -> anyhow::Result<()> {
        if samples == 0 || views == 0 {
            anyhow::bail!("the batch size and the views per batch must be positive");
        }
        let per_sample = (FEATURES + 3 + 3) as u128 * 4 + 8;
        let per_view = 3 * (light_width as u128).pow(2) / 2 * 4;
        let bytes = samples as u128 * per_sample + views as u128 * per_view;
        let what = format!("a batch of {samples} samples over {views} maps");
        nprt_io::ensure_memory(bytes, &what)
    }

    /// Gathers `samples` ((view position in `views`, pixel) pairs) from `views`, with the first
    /// `transfer` coefficients of their transfer vectors (0: none).
    pub fn gather(views: &[&ViewSamples], samples: &[(u32, u32)], transfer: usize) -> Self {
        let mut b = Batch {
            features: Vec::with_capacity(samples.len() * FEATURES),
            radiance: Vec::with_capacity(samples.len() * 3),
            transfer: Vec::with_capacity(samples.len() * 3 * transfer),
            view: Vec::with_capacity(samples.len()),
            scale: Vec::with_capacity(samples.len() * 3),
            lights: views
                .iter()
                .flat_map(|v| v.light.pixels.iter().copied())
                .collect(),
            light_width: views.first().map_or(0, |v| v.light.width),
            picks: None,
        };
        for &(v, p) in samples {
            let view = views[v as usize];
            let (features, radiance) = view.sample(p as usize);
            b.features.extend_from_slice(&features);
            b.radiance.extend_from_slice(&radiance);
            if transfer > 0 {
                view.transfer_into(p as usize, transfer, &mut b.transfer);
            }
            b.view.push(v as i64);
            b.scale.extend_from_slice(&view.light.scale);
        }
        b
    }

    /// Picks `samples` ((view position in `views`, pixel) pairs) from `views`, the training
    /// views numbered `train` (in the same order), for a device that holds the dataset.
    pub fn picked(train: &[usize], views: &[&ViewSamples], samples: &[(u32, u32)]) -> Self {
        let records = samples
            .iter()
            .flat_map(|&(v, p)| [(views[v as usize].first_record() + p as u64) as u32, v])
            .collect();
        Batch {
            features: Vec::new(),
            radiance: Vec::new(),
            transfer: Vec::new(),
            view: samples.iter().map(|&(v, _)| v as i64).collect(),
            scale: Vec::new(),
            lights: Vec::new(),
            light_width: views.first().map_or(0, |v| v.light.width),
            picks: Some(Picks {
                records,
                views: train.iter().map(|&t| t as u32).collect(),
            }),
        }
    }

    /// Batches of at most `batch_size` over a fixed, evenly strided subset of at most
    /// `max_samples` of `views`' pixels, each holding only the maps of the views it touches: the
    /// same pixels every time, for a loss or a level measured across a run.
    pub fn strided<'a>(
        views: &'a [&'a ViewSamples],
        max_samples: usize,
        batch_size: usize,
    ) -> impl Iterator<Item = Batch> + 'a {
        let total: usize = views.iter().map(|v| v.len()).sum();
        let stride = total.div_ceil(max_samples.max(1)).max(1);
        let picked: Vec<(u32, u32)> = views
            .iter()
            .enumerate()
            .flat_map(|(v, view)| (0..view.len() as u32).map(move |p| (v as u32, p)))
            .step_by(stride)
            .collect();
        let batch_size = batch_size.max(1);
        (0..picked.len()).step_by(batch_size).map(move |start| {
            let chunk = &picked[start..(start + batch_size).min(picked.len())];
            let mut used: Vec<u32> = chunk.iter().map(|s| s.0).collect();
            used.dedup();
            let local: Vec<(u32, u32)> = chunk
                .iter()
                .map(|&(v, p)| (used.partition_point(|&u| u < v) as u32, p))
                .collect();
            let sub: Vec<&ViewSamples> = used.iter().map(|&v| views[v as usize]).collect();
            Batch::gather(&sub, &local, 0)
        })
    }

    pub fn len(&self) -> usize {
        self.view.len()
    }

    /// The batch as the CPU engine takes it.
    pub fn samples(&self) -> Samples<'_> {
        Samples {
            features: &self.features,
            radiance: &self.radiance,
            transfer: &self.transfer,
            view: &self.view,
            scale: &self.scale,
            lights: &self.lights,
            light_width: self.light_width,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.view.is_empty()
    }
}
