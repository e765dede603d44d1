//! A trained model's networks on the GPU. The weights are uploaded once; a lighting's code is
//! made by the encoder kernels and stays on the device; a camera's pixels go once through what
//! does not depend on the lighting (each track's transfer network ŝ, or the baseline's gathered
//! inputs), kept on the device; each lighting then runs only the shading networks and the
//! combination, dispatches prepared at the camera's first lighting and recorded again at each
//! later one: a lighting change waits for the queue once, to read the frame back.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use anyhow::Result;
use nprt_gpu::{groups_for, BufferPool, Dispatch, GpuDevice, KeptLast, KernelTime, PooledBuffer};
use nprt_scene::EnvMap;
use nprt_trace::gpu::{GpuMap, SameTexels};

use super::device_shading::DeviceShading;
use super::encoder_run::GpuEncoder;
use super::gpu_pixels::{GpuPixels, PixelChunk, Workspace};
use super::light_code::GpuLightCode;
use super::light_input::GpuLightInput;
use crate::encoding::features::{position_frame, FEATURES};
use crate::encoding::hash_grid;
use crate::encoding::map_norm::MapNorm;
use crate::gpu::kernels::{COMBINE, GBUFFER_FEATURES};
use crate::gpu::layers::network_forward::FirstLayer;
use crate::gpu::layers::network_layout::{NetworkLayout, TrackAt};
use crate::gpu::layers::parameters::ParameterLayout;
use crate::gpu::products::half_layers::{held_halves, HalfLayers, Held, HALF_ROW_BLOCK};
use crate::gpu::products::operands::Bias;
use crate::model::folder::ModelFile;
use crate::network::encoder::Texels;
use crate::network::nprt_net::NprtNet;
use crate::precision::Precision;
use crate::shading::{NetworkEngine, Shading};

/// Most rows per block of dispatches. Fewer blocks mean fewer dispatches to prepare and record
/// (at 65,536 rows a 1920 × 1080 D/S frame was 32 blocks of a dozen dispatches each). A
/// block's widest activations (256 f32 per row, 512 MiB) must also fit one storage binding of
/// the device ([`chunk_rows`]); its kernels' workgroups stay within 65,535 a dimension
/// (`gemm`: 4,096 tiles of 128 rows).
const MAX_CHUNK: usize = 1 << 19;

/// A model's light model and transport networks on the GPU, and the last map it was lit by.
pub struct GpuNetwork {
    gpu: Arc<GpuDevice>,
    /// The weights, as a training step holds them: one flat buffer, and where each tensor
    /// lies in it (with the transport layers' f16 copies in half precision).
    params: wgpu::Buffer,
    net: NetworkLayout,
    encoder: GpuEncoder,
    resolutions: wgpu::Buffer,
    /// The last map a frame's background or encoder input came from.
    map: GpuMap,
    /// The activations every camera's pixels run through, grown as needed.
    workspace: Mutex<Option<Arc<Workspace>>>,
    /// What dropped pixels handed back, for the next camera's.
    pool: BufferPool,
    /// The lighting the shading networks read: a [`GpuLightCode`]'s values, copied in at each
    /// lighting change, then the model's gain per channel.
    light: wgpu::Buffer,
    /// Each track's first shading bias with the light code's share folded in, made anew from
    /// `light` at each lighting change (a linear track's shading network does not read it).
    biases: Vec<wgpu::Buffer>,
    /// The last map's input dispatches, by map, input width and normalisation.
    inputs: KeptLast<(SameTexels, usize, MapNorm), Arc<GpuLightInput>>,
    /// Held from writing a rotation into the kept input's parameters to the submission that
    /// reads it: two lightings made at once would otherwise both read the later one's.
    encoding: Mutex<()>,
    /// Tells the pixels this network made from another's (their kept dispatches read its
    /// buffers).
    id: u64,
    /// The light model's input a map is made into: its width, normalisation and texels.
    encoder_width: usize,
    map_norm: MapNorm,
    texels: Texels,
}

impl GpuNetwork {
    /// Uploads `net`'s weights to the process's GPU device; its radiance is multiplied by
    /// `gain` per channel (the model's level gain), and its light codes made from maps into
    /// `encoder_width`-wide inputs normalised by `map_norm`.
    pub fn new(
        net: &NprtNet,
        gain: [f32; 3],
        encoder_width: usize,
        map_norm: MapNorm,
    ) -> Result<Self> {
        static NETWORKS: AtomicU64 = AtomicU64::new(0);
        let gpu = GpuDevice::get()?;
        let (layout, flat) = ParameterLayout::pack_for(&gpu, net);
        let params = gpu.upload(&flat);
        let layout = NetworkLayout::new(&gpu, &layout, net, false);
        let mut light = vec![0.0; layout.light.code_size() + 3];
        light.extend(gain);
        Ok(GpuNetwork {
            light: gpu.upload(&light),
            biases: (layout.tracks.iter())
                .map(|t| gpu.buffer(t.mlp(t.plan.last().net).layers[0].d_out))
                .collect(),
            inputs: KeptLast::default(),
            encoding: Mutex::new(()),
            id: NETWORKS.fetch_add(1, Ordering::Relaxed),
            encoder_width,
            map_norm,
            texels: net.light.texels(),
            encoder: GpuEncoder::default(),
            params,
            net: layout,
            resolutions: gpu.upload(&hash_grid::resolutions()),
            map: GpuMap::default(),
            workspace: Mutex::new(None),
            pool: BufferPool::default(),
            gpu,
        })
    }

    /// Runs the dense layers in half precision (f16 weights and activations, f32 sums; on
    /// tensor cores where the adapter has them) or, `false`, in f32. Pixels made before must be
    /// made again.
    pub fn set_half(&mut self, half: bool) -> Result<()> {
        if !half {
            self.net.drop_half();
            return Ok(());
        }
        self.gpu.check_half()?;
        if !self.half() {
            let gpu = &*self.gpu;
            self.net.hold_half(gpu);
            gpu.submit(&self.net.half_refresh(gpu, &self.params));
        }
        Ok(())
    }

    /// Whether the dense layers run in half precision ([`Self::set_half`]).
    pub fn half(&self) -> bool {
        !self.net.tracks[0].shading.half.is_empty()
    }

    /// Where the dense layers run, for reports: "f32", "f16 on tensor cores" or "f16".
    pub fn precision_name(&self) -> &'static str {
        match (self.half(), self.gpu.tensor_cores) {
            (false, _) => "f32",
            (true, true) => "f16 on tensor cores",
            (true, false) => "f16",
        }
    }

    /// `map` under `rotation_deg` made into this model's encoder input on the device (see
    /// [`GpuLightInput`]), its texels kept for the frame's background too.
    pub fn light_input(
        &self,
        map: &EnvMap,
        rotation_deg: f32,
        width: usize,
        norm: MapNorm,
    ) -> GpuLightInput {
        let gpu = &*self.gpu;
        let input = GpuLightInput::for_map(gpu, &self.map, map, width, norm, self.texels);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        input.record(gpu, &mut encoder, map, rotation_deg);
        gpu.queue.submit([encoder.finish()]);
        input
    }

    /// The light code of `map` under `rotation_deg`, made into a `width`-wide input under
    /// `norm` and encoded, all queued in one submission and left on the device; the input's
    /// and the encoder's dispatches are kept for the next rotation of the same map.
    pub fn encode_map(
        &self,
        map: &EnvMap,
        rotation_deg: f32,
        width: usize,
        norm: MapNorm,
    ) -> GpuLightCode {
        let gpu = &*self.gpu;
        let key = (SameTexels(map.clone()), width, norm);
        let input = self.inputs.get(key, || {
            Arc::new(GpuLightInput::for_map(
                gpu,
                &self.map,
                map,
                width,
                norm,
                self.texels,
            ))
        });
        let _one_at_a_time = self.encoding.lock().unwrap_or_else(|e| e.into_inner());
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        input.record(gpu, &mut encoder, map, rotation_deg);
        let code = (self.encoder).record_code(gpu, &self.net, &self.params, &mut encoder, &input);
        gpu.queue.submit([encoder.finish()]);
        code
    }

    /// The light code of an encoder input, with the input's divisor per channel, left on the
    /// device: the encoder's dispatches are queued, nothing is waited for.
    pub fn light_code(&self, input: &GpuLightInput) -> GpuLightCode {
        let gpu = &*self.gpu;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let code = (self.encoder).record_code(gpu, &self.net, &self.params, &mut encoder, input);
        gpu.queue.submit([encoder.finish()]);
        code
    }

    /// Uploads the network inputs of a camera's foreground pixels (`rows × FEATURES`) and runs
    /// what does not depend on the lighting.
    pub fn pixels(&self, features: &[f32]) -> GpuPixels {
        let rows = features.len() / FEATURES;
        self.pixels_with(rows, |_, first, n| {
            let rows = &features[first * FEATURES..(first + n) * FEATURES];
            self.pool.hold(self.gpu.upload(rows))
        })
    }

    /// Runs what does not depend on the lighting over `rows` rows, in blocks of
    /// [`chunk_rows`] whose inputs `inputs(pass, first row, rows)` makes.
    fn pixels_with(
        &self,
        rows: usize,
        mut inputs: impl FnMut(&mut wgpu::ComputePass, usize, usize) -> PooledBuffer,
    ) -> GpuPixels {
        let gpu = &*self.gpu;
        let widest = (self.net.tracks.iter())
            .flat_map(|t| {
                let steps = t.plan.steps.iter();
                let layers = steps.flat_map(|s| &t.mlp(s.net).layers);
                layers.map(|l| l.d_out).chain([t.width])
            })
            .max()
            .expect("a network has layers");
        let chunk = chunk_rows(gpu, widest);
        let work = self.workspace(rows.clamp(1, chunk), widest);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let mut chunks = Vec::new();
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            for first in (0..rows).step_by(chunk) {
                let n = chunk.min(rows - first);
                let features = inputs(&mut pass, first, n);
                let kept = (self.net.tracks.iter())
                    .map(|t| self.kept_rows(&mut pass, t, &features, n, &work))
                    .collect();
                chunks.push(PixelChunk {
                    first,
                    rows: n,
                    features,
                    kept,
                });
            }
        }
        gpu.queue.submit([encoder.finish()]);
        GpuPixels {
            rows,
            chunks,
            work,
            rgb: self.pool.take_pooled(gpu, rows.max(1) * 3),
            relight: OnceLock::new(),
            network: self.id,
        }
    }

    /// Records what track `t` keeps of `n` rows of `features` for every lighting: its plan's
    /// steps before the light enters, from its gathered inputs. It keeps what the step the
    /// light enters reads (the last kept step's outputs, or the inputs where the first step
    /// reads the light; in f16 where the workspace is) or, where the light enters at the
    /// combine, the last step's outputs (f32).
    fn kept_rows(
        &self,
        pass: &mut wgpu::ComputePass,
        t: &TrackAt,
        features: &PooledBuffer,
        n: usize,
        work: &Workspace,
    ) -> PooledBuffer {
        let gpu = &*self.gpu;
        let (params, resolutions) = (&self.params, &self.resolutions);
        let (plan, half) = (&t.plan, work.half());
        let held = |width: usize| match half {
            true => held_halves(n, width).div_ceil(2),
            false => n * width,
        };
        // Each unlit step's outputs: the last into what is kept, the others into buffers
        // that go back to the pool once recorded (the pass reads them before any later
        // dispatch can write them).
        let kept = match plan.lit() {
            Some(lit) => self.pool.take_pooled(gpu, held(lit.own_width)),
            None => self.pool.take_pooled(gpu, n * plan.last().outputs),
        };
        let between: Vec<PooledBuffer> = (plan.unlit().iter())
            .take(plan.kept.saturating_sub(1))
            .map(|s| self.pool.take_pooled(gpu, held(s.outputs)))
            .collect();
        let mut list = Vec::new();
        let gathered = &work.f32[0];
        // Where no step runs before the light, the inputs themselves are kept.
        let x = match (plan.kept, half) {
            (0, false) => &*kept,
            _ => gathered,
        };
        list.push(t.record_inputs(gpu, params, resolutions, [features, x], n));
        if (plan.kept, half) == (0, true) {
            list.push(gpu.half_rows([n, t.width, t.width], gathered, &kept));
        }
        let mut input = Held::F32(gathered);
        for (i, step) in plan.unlit().iter().enumerate() {
            let m = t.mlp(step.net);
            let out = match (i + 1 == plan.kept, plan.lit()) {
                (true, Some(_)) => work.held(&kept),
                (true, None) => Held::F32(&kept),
                (false, _) => work.held(&between[i]),
            };
            let first = FirstLayer {
                own_row: step.own_row,
                count: step.own_width,
                bias: Bias::Column(params, m.layers[0].bias.offset),
            };
            m.record_forward(gpu, &mut list, params, input, n, first, &work.targets(m, out));
            input = out;
        }
        for d in list {
            d.record(pass);
        }
        kept
    }

    /// The workspace for blocks of `rows` rows of activations at most `widest` wide: the kept
    /// one where it is large enough and of this precision, else a new one, kept instead.
    fn workspace(&self, rows: usize, widest: usize) -> Arc<Workspace> {
        let mut kept = self.workspace.lock().unwrap_or_else(|e| e.into_inner());
        let half = self.half();
        if let Some(w) = kept.as_ref().filter(|w| w.rows >= rows && w.half() == half) {
            return w.clone();
        }
        let gpu = &*self.gpu;
        let work = Arc::new(Workspace {
            rows,
            f32: [0, 1].map(|_| gpu.buffer(rows * widest)),
            f16: half.then(|| [0, 1].map(|_| gpu.half_buffer(held_halves(rows, widest)))),
            outputs: (self.net.tracks.iter())
                .map(|t| gpu.buffer(rows * t.plan.last().outputs))
                .collect(),
        });
        *kept = Some(work.clone());
        work
    }

    /// What a lighting change runs on `px`, prepared at its first: each track's shading
    /// network with the light code's share folded into its first bias (none where the light
    /// enters at the combine: its outputs are kept), then the combination into radiance (times
    /// the map's divisor and the gain), all reading the light slot.
    fn relight_dispatches<'p>(&self, px: &'p GpuPixels) -> &'p [Dispatch] {
        assert_eq!(
            px.network, self.id,
            "pixels relit by a network other than the one that made them"
        );
        assert_eq!(
            px.work.half(),
            self.half(),
            "pixels made in one precision, relit in the other"
        );
        px.relight.get_or_init(|| self.prepare_relight(px))
    }

    fn prepare_relight(&self, px: &GpuPixels) -> Vec<Dispatch> {
        let gpu = &*self.gpu;
        let mut list = Vec::new();
        let params = &self.params;
        // b' = b + ê·W[code rows]: the light slot's code through the first layer's code rows.
        for (t, bias) in self.net.tracks.iter().zip(&self.biases) {
            if t.plan.lit().is_some() {
                list.push(t.record_code_share(gpu, params, &self.light, 1, bias));
            }
        }
        for chunk in &px.chunks {
            for ((t, kept), (bias, out)) in (self.net.tracks.iter())
                .zip(&chunk.kept)
                .zip(self.biases.iter().zip(&px.work.outputs))
            {
                // The step the light enters, on what was kept ([ŝ, ê] with ŝ's rows first,
                // or the baseline's [ê, inputs]).
                let Some(step) = t.plan.lit() else { continue };
                let first = FirstLayer {
                    own_row: step.own_row,
                    count: step.own_width,
                    bias: Bias::Column(bias, 0),
                };
                let m = t.mlp(step.net);
                let to = px.work.targets(m, Held::F32(out));
                let x = px.work.held(kept);
                m.record_forward(gpu, &mut list, params, x, chunk.rows, first, &to);
            }
            // The tracks' radiance summed into rgb one track per dispatch (any number of
            // tracks), the last multiplied by the map's divisor and the model's gain.
            let n = self.net.tracks.len();
            let outputs = (self.net.tracks.iter())
                .zip(&px.work.outputs)
                .zip(&chunk.kept);
            for (k, ((t, out), kept)) in outputs.enumerate() {
                let out = match t.plan.lit() {
                    Some(_) => out,
                    None => kept,
                };
                let params = [
                    chunk.rows,
                    t.kind.code() as usize,
                    usize::from(k > 0),
                    usize::from(k + 1 == n),
                    chunk.first,
                    self.net.light.code_size(),
                    t.light.coefficients(),
                    0,
                ];
                // One code for every row (code_stride 0): the views binding is not read.
                list.push(gpu.prepare(
                    &COMBINE,
                    &params.map(|v| v as u32),
                    &[&chunk.features, out, &self.light, &chunk.features, &px.rgb],
                    groups_for(chunk.rows),
                ));
            }
        }
        list
    }

    /// Records the copy of `code` (and its divisor) into the light slot the shading networks
    /// read.
    fn use_light(&self, encoder: &mut wgpu::CommandEncoder, code: &GpuLightCode) {
        assert_eq!(
            code.values,
            self.net.light.code_size(),
            "a light code of another light model"
        );
        let bytes = 4 * (code.values + 3) as u64;
        encoder.copy_buffer_to_buffer(&code.buffer, 0, &self.light, 0, bytes);
    }

    /// Radiance (`rows × 3`) of `px` under the light `code`, each channel multiplied by the
    /// code's divisor (the map's normalisation) and the model's gain.
    pub fn radiance(&self, px: &GpuPixels, code: &GpuLightCode) -> Vec<f32> {
        if px.rows == 0 {
            return Vec::new();
        }
        self.queue_radiance(px, code, &mut |_, _| {});
        self.gpu.read(&px.rgb, px.rows * 3)
    }
}

impl Shading for GpuNetwork {
    type Code = GpuLightCode;
    type Rows = GpuPixels;

    fn light_code(&self, map: &EnvMap, rotation_deg: f32) -> GpuLightCode {
        self.encode_map(map, rotation_deg, self.encoder_width, self.map_norm)
    }

    fn pixels(&self, features: &[f32]) -> GpuPixels {
        GpuNetwork::pixels(self, features)
    }

    fn radiance(&self, px: &GpuPixels, light: &GpuLightCode) -> Vec<f32> {
        GpuNetwork::radiance(self, px, light)
    }

    fn precision(&self) -> Precision {
        match self.half() {
            true => Precision::F16,
            false => Precision::F32,
        }
    }

    fn set_precision(&mut self, precision: Precision) -> Result<()> {
        self.set_half(precision == Precision::F16)
    }

    fn describe(&self) -> String {
        match self.half() {
            false => format!("GPU kernels on {}", self.gpu.adapter),
            true => format!(
                "GPU kernels on {} ({})",
                self.gpu.adapter,
                self.precision_name()
            ),
        }
    }

    fn settle(&self) -> Result<()> {
        self.gpu.wait();
        Ok(())
    }

    fn host_waits(&self) -> Option<u64> {
        Some(self.gpu.host_waits())
    }
}

impl DeviceShading for GpuNetwork {
    fn maps(&self) -> &GpuMap {
        &self.map
    }

    fn pixels_of_gbuffer(
        &self,
        samples: &wgpu::Buffer,
        pixels: usize,
        bounds: &[[f32; 3]; 2],
    ) -> GpuPixels {
        let (lo, extent) = position_frame(bounds);
        self.pixels_with(pixels, |pass, first, n| {
            let features = self.pool.take_pooled(&self.gpu, n * FEATURES);
            let mut params = vec![n as u32, first as u32, 0, 0];
            params.extend(
                [lo.extend(0.0), extent.extend(0.0)]
                    .iter()
                    .flat_map(|v| v.to_array().map(f32::to_bits)),
            );
            self.gpu.dispatch(
                pass,
                &GBUFFER_FEATURES,
                &params,
                &[samples, &features],
                groups_for(n),
            );
            features
        })
    }

    fn profile_relight(&self, px: &GpuPixels, code: &GpuLightCode) -> Result<Vec<KernelTime>> {
        let mut encoder = self.gpu.device.create_command_encoder(&Default::default());
        self.use_light(&mut encoder, code);
        self.gpu.queue.submit([encoder.finish()]);
        let input = self.inputs.kept();
        let run = self.encoder.kept();
        let encoding = input.iter().flat_map(|i| i.dispatches());
        let encoding = encoding.chain(run.iter().flat_map(|r| r.dispatches()));
        let dispatches: Vec<&Dispatch> = encoding.chain(self.relight_dispatches(px)).collect();
        self.gpu.profile(&dispatches)
    }

    fn queue_radiance(
        &self,
        px: &GpuPixels,
        code: &GpuLightCode,
        after: &mut dyn FnMut(&mut wgpu::ComputePass, &wgpu::Buffer),
    ) {
        let gpu = &*self.gpu;
        let dispatches = self.relight_dispatches(px);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.use_light(&mut encoder, code);
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            for d in dispatches {
                d.record(&mut pass);
            }
            after(&mut pass, &px.rgb);
        }
        gpu.queue.submit([encoder.finish()]);
    }
}

/// The GPU kernels: networks on the process's one wgpu device.
pub struct GpuKernels;

impl NetworkEngine for GpuKernels {
    type Network = GpuNetwork;

    fn network(file: &ModelFile, net: NprtNet) -> Result<GpuNetwork> {
        let (width, norm) = (file.config.encoder_width, file.config.map_norm);
        GpuNetwork::new(&net, file.output_gain(), width, norm)
    }
}

/// Rows per block of dispatches on `gpu` for activations `widest` f32 wide: [`MAX_CHUNK`], or
/// fewer where one storage binding holds less (WebGPU's portable minimum is 128 MiB), a
/// multiple of the half-precision layers' row blocks.
fn chunk_rows(gpu: &GpuDevice, widest: usize) -> usize {
    let fit = gpu.max_binding_bytes() as usize / (4 * widest.next_multiple_of(16));
    (fit / HALF_ROW_BLOCK * HALF_ROW_BLOCK).clamp(HALF_ROW_BLOCK, MAX_CHUNK)
}
