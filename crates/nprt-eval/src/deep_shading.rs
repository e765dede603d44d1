//! The Deep Shading baseline (Nalbach et al. 2017): a per-scene U-Net from G-buffer images to
//! radiance, trained on the same dataset as the Neural PRT designs. The paper's comparison
//! gives it the lighting too: the map goes through the same light encoder (trained jointly)
//! and its code is added to the U-Net's bottleneck. Widths are chosen for about the parameter
//! count of the Neural PRT designs (≈200 K without the encoder).

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use burn::module::Module;
use burn::nn::conv::Conv2d;
use burn::nn::pool::{MaxPool2d, MaxPool2dConfig};
use burn::nn::Linear;
use burn::optim::{AdamConfig, GradientsParams};
use burn::tensor::activation::relu;
use burn::tensor::{Tensor, TensorData};
use glam::Vec3;
use nprt_net::curves::{plot, read_csv, write_csv};
use nprt_net::data::gbuffer_features;
use nprt_net::encoder::CODE_SIZE;
use nprt_net::layers::conv2d;
use nprt_net::layers::Mlp;
use nprt_net::model::{load_weights, save_weights};
use nprt_net::train::LossRow;
use nprt_net::{Activation, Device, Init, LightEncoder, LightInput, FEATURES};
use nprt_scene::EnvMap;
use nprt_trace::GBuffer;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use nprt_data::views::ImageView;

pub const TAG: &str = "deep-shading";
pub const CONFIG_FILE: &str = "deep-shading.json";
const WEIGHTS_FILE: &str = "weights.safetensors";
/// Channels of the encoder levels (full, ½, ¼ resolution) and of the ⅛-resolution bottleneck.
const WIDTHS: [usize; 4] = [16, 32, 64, 64];

#[derive(Module, Debug)]
pub struct DeepShading {
    pub light: LightEncoder,
    /// Two 3×3 convolutions per encoder level.
    pub down: Vec<Conv2d>,
    pub bottleneck: Vec<Conv2d>,
    /// The light code as a per-channel offset of the bottleneck.
    pub code: Linear,
    /// One 3×3 convolution per decoder level, on [upsampled, skip].
    pub up: Vec<Conv2d>,
    pub out: Conv2d,
    pub pool: MaxPool2d,
}

fn upsample(x: Tensor<4>) -> Tensor<4> {
    let [b, c, h, w] = x.dims();
    x.reshape([b, c, h, 1, w, 1])
        .expand([b, c, h, 2, w, 2])
        .reshape([b, c, 2 * h, 2 * w])
}

impl DeepShading {
    pub fn new(init: &mut Init, encoder_width: usize) -> Self {
        let light = LightEncoder::new(init, encoder_width);
        let mut down = Vec::new();
        let mut c_in = FEATURES;
        for &w in &WIDTHS[..3] {
            down.push(conv2d(init, c_in, w, 3));
            down.push(conv2d(init, w, w, 3));
            c_in = w;
        }
        let b = WIDTHS[3];
        let bottleneck = vec![conv2d(init, WIDTHS[2], b, 3), conv2d(init, b, b, 3)];
        let code = Mlp::new(init, &[CODE_SIZE, b], Activation::Relu)
            .layers
            .remove(0);
        let up = vec![
            conv2d(init, b + WIDTHS[2], WIDTHS[1], 3),
            conv2d(init, WIDTHS[1] + WIDTHS[1], WIDTHS[0], 3),
            conv2d(init, WIDTHS[0] + WIDTHS[0], WIDTHS[0], 3),
        ];
        DeepShading {
            light,
            down,
            bottleneck,
            code,
            up,
            out: conv2d(init, WIDTHS[0], 3, 1),
            pool: MaxPool2dConfig::new([2, 2]).with_strides([2, 2]).init(),
        }
    }

    /// Parameters without the light encoder (comparable to the designs' transport counts).
    pub fn unet_params(&self) -> usize {
        self.num_params() - self.light.num_params()
    }

    /// Radiance [B, 3, H, W] from G-buffer features [B, 19, H, W] (H, W multiples of 8),
    /// pre-processed maps [B, 3, W/2, W] and map means [B].
    pub fn forward(&self, features: Tensor<4>, light: Tensor<4>, scale: Tensor<1>) -> Tensor<4> {
        let code = self.light.forward(light);
        let mut x = features;
        let mut skips = Vec::new();
        for pair in self.down.chunks(2) {
            x = relu(pair[1].forward(relu(pair[0].forward(x))));
            skips.push(x.clone());
            x = self.pool.forward(x);
        }
        x = relu(self.bottleneck[0].forward(x));
        let [b, c, h, w] = x.dims();
        x = x + self
            .code
            .forward(code)
            .reshape([b, c, 1, 1])
            .expand([b, c, h, w]);
        x = relu(self.bottleneck[1].forward(x));
        for conv in &self.up {
            let skip = skips.pop().expect("one skip per level");
            x = relu(conv.forward(Tensor::cat(vec![upsample(x), skip], 1)));
        }
        let [b, _, h, w] = x.dims();
        self.out.forward(x).exp() * scale.reshape([b, 1, 1, 1]).expand([b, 3, h, w])
    }
}

/// A view's G-buffer as a [19, H', W'] feature image, zero on the background and padded to
/// multiples of 8; returns the padded size too.
pub fn feature_image(
    bounds: &[[f32; 3]; 2],
    g: &GBuffer,
    width: usize,
    height: usize,
) -> (Vec<f32>, usize, usize) {
    let (pw, ph) = (width.div_ceil(8) * 8, height.div_ceil(8) * 8);
    let mut img = vec![0.0; FEATURES * pw * ph];
    for i in (0..g.mask.len()).filter(|&i| g.mask[i] > 0.5) {
        let f = gbuffer_features(bounds, g, i);
        let (x, y) = (i % width, i / width);
        for (k, v) in f.iter().enumerate() {
            img[k * pw * ph + y * pw + x] = *v;
        }
    }
    (img, pw, ph)
}

/// The model folder's config.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DeepShadingFile {
    pub format: String,
    pub version: u32,
    pub encoder_width: usize,
    pub bounds: [[f32; 3]; 2],
    pub scene: String,
    pub scene_hash: String,
    pub dataset_hash: String,
    pub unet_params: usize,
    pub encoder_params: usize,
    pub options: DeepShadingOptions,
    pub epochs_done: usize,
    pub seconds: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DeepShadingOptions {
    pub epochs: usize,
    /// Whole views per step.
    pub batch_views: usize,
    pub learning_rate: f64,
    pub seed: u64,
    pub encoder_width: usize,
}

/// A trained Deep Shading network, ready to shade.
pub struct DeepShadingModel {
    pub file: DeepShadingFile,
    net: DeepShading,
    device: Device,
}

pub fn read_file(dir: &Path) -> Result<DeepShadingFile> {
    let path = dir.join(CONFIG_FILE);
    let text = std::fs::read_to_string(&path).with_context(|| {
        format!(
            "'{}' is not a Deep Shading model folder (no readable {CONFIG_FILE})",
            dir.display()
        )
    })?;
    let f: DeepShadingFile = serde_json::from_str(&text)
        .with_context(|| format!("'{}' is malformed", path.display()))?;
    if f.format != TAG || f.version != 1 {
        bail!(
            "'{}' is not a version-1 Deep Shading config",
            path.display()
        );
    }
    Ok(f)
}

impl DeepShadingModel {
    pub fn load(dir: &Path, device: &Device) -> Result<Self> {
        let file = read_file(dir)?;
        let mut net = DeepShading::new(&mut Init::new(0, device), file.encoder_width);
        load_weights(&dir.join(WEIGHTS_FILE), &mut net, TAG)?;
        Ok(DeepShadingModel {
            file,
            net,
            device: device.clone(),
        })
    }

    /// Radiance of every pixel of a `width`×`height` G-buffer under `map` rotated by
    /// `rotation_deg` (background pixels 0).
    pub fn shade(
        &self,
        g: &GBuffer,
        width: usize,
        height: usize,
        map: &EnvMap,
        rotation_deg: f32,
    ) -> Vec<Vec3> {
        let (img, pw, ph) = feature_image(&self.file.bounds, g, width, height);
        let light = LightInput::new(map, rotation_deg, self.file.encoder_width);
        let lw = light.width;
        let out = self.net.forward(
            Tensor::from_data(TensorData::new(img, [1, FEATURES, ph, pw]), &self.device),
            Tensor::from_data(
                TensorData::new(light.pixels, [1, 3, lw / 2, lw]),
                &self.device,
            ),
            Tensor::from_data(TensorData::new(vec![light.scale], [1]), &self.device),
        );
        let data = out.into_data();
        let v = data.as_slice::<f32>().expect("f32 output");
        (0..width * height)
            .map(|i| {
                let (x, y) = (i % width, i / width);
                if g.mask[i] > 0.5 {
                    Vec3::new(
                        v[y * pw + x],
                        v[pw * ph + y * pw + x],
                        v[2 * pw * ph + y * pw + x],
                    )
                } else {
                    Vec3::ZERO
                }
            })
            .collect()
    }
}

/// What training needs of each view.
struct Sample {
    features: Vec<f32>,
    radiance: Vec<f32>,
    mask: Vec<f32>,
    light: LightInput,
}

fn prepare(
    views: &[ImageView],
    maps: &[EnvMap],
    bounds: &[[f32; 3]; 2],
    encoder_width: usize,
) -> Result<(Vec<Sample>, usize, usize)> {
    let (w, h) = (views[0].width, views[0].height);
    if views.iter().any(|v| (v.width, v.height) != (w, h)) {
        bail!("Deep Shading trains on views of one resolution");
    }
    let samples = views
        .iter()
        .map(|v| {
            let (features, pw, ph) = feature_image(bounds, &v.gbuffer, w, h);
            let mut radiance = vec![0.0; 3 * pw * ph];
            let mut mask = vec![0.0; pw * ph];
            for i in 0..w * h {
                let j = (i / w) * pw + i % w;
                mask[j] = v.gbuffer.mask[i];
                for c in 0..3 {
                    radiance[c * pw * ph + j] = v.radiance[i][c] * mask[j];
                }
            }
            Sample {
                features,
                radiance,
                mask,
                light: LightInput::new(&maps[v.record.map], v.record.rotation_deg, encoder_width),
            }
        })
        .collect();
    Ok((samples, w.div_ceil(8) * 8, h.div_ceil(8) * 8))
}

/// The masked log-L1 loss and the tensors of a batch of views.
fn batch_loss(
    net: &DeepShading,
    batch: &[&Sample],
    pw: usize,
    ph: usize,
    device: &Device,
) -> Tensor<1> {
    let b = batch.len();
    let cat = |f: fn(&Sample) -> &Vec<f32>| {
        batch
            .iter()
            .flat_map(|s| f(s).iter().copied())
            .collect::<Vec<f32>>()
    };
    let lw = batch[0].light.width;
    let features = Tensor::from_data(
        TensorData::new(cat(|s| &s.features), [b, FEATURES, ph, pw]),
        device,
    );
    let reference = Tensor::from_data(
        TensorData::new(cat(|s| &s.radiance), [b, 3, ph, pw]),
        device,
    );
    let mask = Tensor::<4>::from_data(TensorData::new(cat(|s| &s.mask), [b, 1, ph, pw]), device);
    let light = Tensor::from_data(
        TensorData::new(cat(|s| &s.light.pixels), [b, 3, lw / 2, lw]),
        device,
    );
    let scale = Tensor::from_data(
        TensorData::new(batch.iter().map(|s| s.light.scale).collect::<Vec<_>>(), [b]),
        device,
    );
    let pred = net.forward(features, light, scale);
    let mask3 = mask.clone().expand([b, 3, ph, pw]);
    let err = nprt_net::loss::log_l1_map(pred, reference) * mask3;
    err.sum() / (mask.sum() * 3.0).clamp_min(1.0)
}

/// Trains (or resumes, from the last finished epoch) a Deep Shading network on the training
/// views, with the validation loss on the test views after every epoch.
#[allow(clippy::too_many_arguments)]
pub fn train(
    train_views: &[ImageView],
    test_views: &[ImageView],
    maps: &[EnvMap],
    base: DeepShadingFile,
    out: &Path,
    device: &Device,
    progress: bool,
) -> Result<DeepShadingFile> {
    let opts = base.options.clone();
    if train_views.is_empty() {
        bail!("no training views");
    }
    std::fs::create_dir_all(out).with_context(|| format!("cannot create '{}'", out.display()))?;
    let ad = device.clone().autodiff();
    let mut net = DeepShading::new(&mut Init::new(opts.seed, &ad), opts.encoder_width);
    let mut file = base;
    file.unet_params = net.unet_params();
    file.encoder_params = net.light.num_params();
    let mut rows: Vec<LossRow> = Vec::new();
    if let Ok(prev) = read_file(out) {
        if prev.options.seed != opts.seed
            || prev.options.batch_views != opts.batch_views
            || prev.options.learning_rate != opts.learning_rate
            || prev.dataset_hash != file.dataset_hash
        {
            bail!(
                "'{}' holds a Deep Shading model of other settings or data; choose another folder",
                out.display()
            );
        }
        load_weights(&out.join(WEIGHTS_FILE), &mut net, TAG)?;
        file.epochs_done = prev.epochs_done;
        file.seconds = prev.seconds;
        rows = read_csv(&out.join("loss.csv"))?;
    }
    let (train_s, pw, ph) = prepare(train_views, maps, &file.bounds, opts.encoder_width)?;
    let (test_s, tpw, tph) = prepare(test_views, maps, &file.bounds, opts.encoder_width)?;
    // Adam restarts on resume (its moments are not saved); the weights carry over.
    let mut optim = AdamConfig::new().with_epsilon(1e-8).init();
    let steps_per_epoch = train_s.len().div_ceil(opts.batch_views);
    let bar = nprt_io::progress_bar(
        progress,
        ((opts.epochs.saturating_sub(file.epochs_done)) * steps_per_epoch) as u64,
        "Deep Shading",
        "steps",
    );
    let start = Instant::now();
    let seconds_before = file.seconds;
    for epoch in file.epochs_done..opts.epochs {
        let mut order: Vec<usize> = (0..train_s.len()).collect();
        order.shuffle(&mut Pcg64Mcg::seed_from_u64(
            opts.seed ^ (epoch as u64).wrapping_mul(0x9e37_79b9),
        ));
        let mut sum = 0.0;
        for (step, chunk) in order.chunks(opts.batch_views).enumerate() {
            let batch: Vec<&Sample> = chunk.iter().map(|&i| &train_s[i]).collect();
            let loss = batch_loss(&net, &batch, pw, ph, &ad);
            let value = loss.clone().into_scalar::<f32>() as f64;
            if !value.is_finite() {
                bail!(
                    "Deep Shading training diverged (loss {value}) in epoch {}",
                    epoch + 1
                );
            }
            sum += value;
            let grads = GradientsParams::from_grads(loss.backward(), &net);
            net = optim.step(opts.learning_rate, net, grads);
            bar.inc(1);
            bar.set_message(format!(
                "epoch {}/{} step {}/{steps_per_epoch} loss {:.4}",
                epoch + 1,
                opts.epochs,
                step + 1,
                sum / (step + 1) as f64
            ));
        }
        let valid = net.valid();
        let val = if test_s.is_empty() {
            f64::NAN
        } else {
            test_s
                .chunks(opts.batch_views)
                .map(|c| {
                    batch_loss(&valid, &c.iter().collect::<Vec<_>>(), tpw, tph, device)
                        .into_scalar::<f32>() as f64
                        * c.len() as f64
                })
                .sum::<f64>()
                / test_s.len() as f64
        };
        file.epochs_done = epoch + 1;
        file.seconds = seconds_before + start.elapsed().as_secs_f64();
        rows.push(LossRow {
            step: ((epoch + 1) * steps_per_epoch) as u64,
            epoch: (epoch + 1) as f64,
            samples: ((epoch + 1) * train_s.len()) as u64,
            seconds: file.seconds,
            train: Some(sum / steps_per_epoch as f64),
            val: Some(val),
        });
        save_weights(&out.join(WEIGHTS_FILE), &valid, TAG)?;
        write_csv(&out.join("loss.csv"), &rows)?;
        plot(&out.join("loss.png"), &rows, "Deep Shading (U-Net)")?;
        let json = serde_json::to_vec_pretty(&file)?;
        nprt_io::write_file(&out.join(CONFIG_FILE), &json)?;
        if !progress {
            eprintln!(
                "Deep Shading epoch {}/{}: train {:.4}, val {val:.4}",
                epoch + 1,
                opts.epochs,
                sum / steps_per_epoch as f64
            );
        }
    }
    bar.finish_and_clear();
    Ok(file)
}
