//! The transport tracks of a design on the CPU engine: forward, the training loss and backward
//! for a whole batch, block by block on all cores, given the light codes the light model made;
//! and the radiance of a frame's pixels for one light code, from what a still camera keeps of
//! each track ([`KeptRows`]). A linear track's shading outputs are transfer coefficients, each
//! term's value their dot product with the light code.

use std::ops::Range;

use rayon::prelude::*;

use super::accumulate;
use super::dense::{Pass, SharedInput, Tape};
use super::matmul::MatRef;
use super::samples::Samples;
use crate::encoding::features::FEATURES;
use crate::encoding::hash_grid;
use crate::loss::Loss;
use crate::network::light_entry::LightEntry;
use crate::network::mlp::Mlp;
use crate::network::nprt_net::NprtNet;
use crate::network::track::Track;
use crate::network::track_plan::{Step, TrackPlan};
use crate::parameters::Parameters;

mod kept_rows;
mod transfer_vectors;

pub use kept_rows::KeptRows;

/// Rows per block: small enough that a block's activations stay in the caches, large enough
/// for efficient matrix products.
const BLOCK: usize = 512;
/// A batch's blocks are cut into this many runs of consecutive blocks, one gradient sum each,
/// added in order: the result does not depend on the number of threads.
const RUNS: usize = 8;
/// The group of every row when one light code lights them all.
const ONE_GROUP: [u32; BLOCK] = [0; BLOCK];

/// Loss and gradients of one batch.
pub struct TransportGradients {
    /// The batch's mean loss: over its radiance values, or its transfer coefficients.
    pub loss: f64,
    /// Per track, gradients of its grid, transfer and shading networks.
    pub tracks: Vec<Track>,
    /// Gradient at each view's light code, `views × code size`.
    pub codes: Vec<f32>,
}

/// A track's state over one block; its buffers are reused from block to block, and kept by
/// each worker thread from call to call ([`with_passes`]).
#[derive(Default)]
struct TrackPass {
    /// Gathered inputs (empty when the track reads all features and has no grid).
    x: Vec<f32>,
    /// Gradient at those inputs (for the grid's part).
    d_x: Vec<f32>,
    /// Each step's tape, in the order of the track's plan.
    tapes: Vec<Tape>,
    /// Each term's value per row and channel: the exp of the shading network's outputs, or
    /// for a linear track their dot product with the light code.
    terms: Vec<f32>,
    /// The gradient at each step's outputs.
    d: Vec<Vec<f32>>,
}

impl TrackPass {
    /// The last step's outputs (when it ran).
    fn outputs(&self) -> &[f32] {
        self.tapes.last().map_or(&[], |t| t.output())
    }

    /// The gradient at the last step's outputs.
    fn d_outputs(&mut self) -> &mut Vec<f32> {
        self.d.last_mut().expect("sized by backward")
    }
}

thread_local! {
    /// Each thread's block buffers, kept between calls: buffers allocated anew for every
    /// block or step came as freshly mapped pages each time, whose clearing by the kernel was
    /// 19% of a D/S frame in perf.
    static PASSES: std::cell::Cell<Vec<TrackPass>> = const { std::cell::Cell::new(Vec::new()) };
}

/// Runs `f` with `tracks` block buffers of this thread's. They are taken out while `f` runs,
/// so a nested call on the same thread gets fresh ones instead of aliasing them.
fn with_passes<R>(tracks: usize, f: impl FnOnce(&mut [TrackPass]) -> R) -> R {
    let mut passes = PASSES.take();
    if passes.len() < tracks {
        passes.resize_with(tracks, TrackPass::default);
    }
    let result = f(&mut passes[..tracks]);
    PASSES.set(passes);
    result
}

/// What a backward pass starts from: the gradient at each row's radiance (`rows × 3`), or at
/// its transfer vector (`rows × K × 3`).
#[derive(Clone, Copy)]
enum Upstream<'a> {
    Radiance(&'a [f32]),
    Transfer(&'a [f32]),
}

/// What the first of a run of a track's steps reads.
#[derive(Clone, Copy)]
enum StepInput<'a> {
    /// The rows' features, from which the track gathers its inputs.
    Features(&'a [f32]),
    /// The outputs of the step before it, as a still camera keeps them, for this many rows.
    Kept(&'a [f32], usize),
}

/// The light codes of a block: each view's code, and each row's view.
#[derive(Clone, Copy)]
struct Lighting<'a> {
    codes: &'a [f32],
    view: &'a [u32],
}

impl Lighting<'_> {
    /// The code of row `r`, `size` values.
    fn code(&self, r: usize, size: usize) -> &[f32] {
        &self.codes[self.view[r] as usize * size..][..size]
    }
}

impl Track {
    /// Whether the first layer reads the features as they are.
    fn reads_features(&self) -> bool {
        self.kind.reads_all() && self.grid.is_none()
    }

    /// The light code as `step`'s first layer reads it; None where it does not.
    fn shared<'a>(step: &Step, light: Lighting<'a>) -> Option<SharedInput<'a>> {
        step.code_rows.clone().map(|weight_rows| SharedInput {
            weight_rows,
            values: light.codes,
            group: light.view,
        })
    }

    /// Values per row of [`TrackPass::terms`]: 3 per term.
    fn term_values(&self) -> usize {
        self.kind.outputs()
    }

    /// This track's inputs of each row (with the grid's encoding after them), gathered into
    /// `x` unless it reads the features as they are; the rows as a matrix.
    fn inputs<'a>(&self, features: &'a [f32], x: &'a mut Vec<f32>, n: usize) -> MatRef<'a> {
        if self.reads_features() {
            return MatRef::new(features, n, FEATURES);
        }
        let (width, inputs) = (self.width(), self.kind.inputs());
        x.resize(n * width, 0.0);
        for (row, f) in x
            .chunks_exact_mut(width)
            .zip(features.chunks_exact(FEATURES))
        {
            let (own, encoded) = row.split_at_mut(inputs.len());
            own.iter_mut().zip(&inputs).for_each(|(v, &i)| *v = f[i]);
            if let Some(grid) = &self.grid {
                hash_grid::encode(
                    &grid.table,
                    &hash_grid::corners(hash_grid::position(f)),
                    encoded,
                );
            }
        }
        self.gathered(features, x, n)
    }

    /// The rows' inputs as [`Self::inputs`] left them for these `features`: backward reads
    /// them from there rather than gathering and encoding them again.
    fn gathered<'a>(&self, features: &'a [f32], x: &'a [f32], n: usize) -> MatRef<'a> {
        if self.reads_features() {
            MatRef::new(features, n, FEATURES)
        } else {
            MatRef::new(x, n, self.width())
        }
    }

    /// Adds to the grid's gradient what the gradient at the first layer's inputs (`d_x`,
    /// `rows × width`) sends back through the encoding.
    fn grid_backward(&self, features: &[f32], d_x: &[f32], grads: &mut Track) {
        let Some(grad) = &mut grads.grid else { return };
        let own = self.kind.inputs().len();
        for (d, f) in d_x
            .chunks_exact(self.width())
            .zip(features.chunks_exact(FEATURES))
        {
            hash_grid::scatter(
                &mut grad.table,
                &hash_grid::corners(hash_grid::position(f)),
                &d[own..],
            );
        }
    }

    /// Forward over `n` rows of `features` under `light`. `known` holds what a still camera
    /// keeps of these rows ([`Self::kept_width`]) when it is known already: the outputs of the
    /// plan's steps before the light enters, which do not run again.
    fn forward(
        &self,
        features: &[f32],
        light: Lighting,
        n: usize,
        known: Option<&[f32]>,
        pass: &mut TrackPass,
        purpose: Pass,
    ) {
        let plan = self.plan();
        let (start, input) = match known {
            Some(kept) => (plan.kept, StepInput::Kept(kept, n)),
            None => (0, StepInput::Features(features)),
        };
        self.run_steps(&plan, start..plan.steps.len(), input, light, pass, purpose);
        let TrackPass { tapes, terms, .. } = pass;
        let out = match (start == plan.steps.len(), known) {
            (true, Some(outputs)) => outputs,
            _ => tapes.last().expect("a step ran").output(),
        };
        terms.clear();
        let LightEntry::Combine { k } = self.light else {
            terms.extend(out.iter().map(|o| o.exp()));
            return;
        };
        // Term t, channel c: Σ_j T[(t·K + j)·3 + c] · e[j·3 + c].
        let per_row = self.term_values();
        terms.resize(n * per_row, 0.0);
        for (r, (terms, t)) in (terms.chunks_exact_mut(per_row))
            .zip(out.chunks_exact(per_row * k))
            .enumerate()
        {
            let code = light.code(r, 3 * k);
            for (term, coeffs) in terms.chunks_exact_mut(3).zip(t.chunks_exact(3 * k)) {
                for (c, v) in term.iter_mut().enumerate() {
                    *v = (0..k).map(|j| coeffs[j * 3 + c] * code[j * 3 + c]).sum();
                }
            }
        }
    }

    /// Runs the plan's `steps` over the rows, each on its tape in `pass`, the first reading
    /// `input`.
    fn run_steps(
        &self,
        plan: &TrackPlan,
        steps: Range<usize>,
        input: StepInput,
        light: Lighting,
        pass: &mut TrackPass,
        purpose: Pass,
    ) {
        let n = match input {
            StepInput::Features(features) => features.len() / FEATURES,
            StepInput::Kept(_, rows) => rows,
        };
        pass.tapes.resize_with(plan.steps.len(), Tape::default);
        let first = steps.start;
        for i in steps {
            let step = &plan.steps[i];
            let (before, here) = pass.tapes.split_at_mut(i);
            let x = match (i == first, input) {
                (true, StepInput::Kept(kept, _)) => MatRef::new(kept, n, step.own_width),
                (true, StepInput::Features(features)) => self.inputs(features, &mut pass.x, n),
                (false, _) => MatRef::new(before[i - 1].output(), n, step.own_width),
            };
            let shared = Self::shared(step, light);
            (self.mlp(step.net)).forward(x, shared.as_ref(), &mut here[0], purpose);
        }
    }

    /// Radiance of row `r` before the map's scale.
    fn radiance(&self, pass: &TrackPass, features: &[f32], r: usize) -> [f32; 3] {
        let f = &features[r * FEATURES..];
        let e = &pass.terms[r * self.term_values()..];
        self.kind.radiance(f, e)
    }

    /// The gradient at the shading network's outputs (the last step's), from the gradient
    /// `dr` at this track's radiance (before the scale); a linear track adds the gradient at
    /// each row's light code to `d_codes`.
    fn d_outputs(
        &self,
        pass: &mut TrackPass,
        features: &[f32],
        dr: &[f32],
        light: Lighting,
        d_codes: &mut [f32],
    ) {
        let (outs, per_row) = (self.shading.d_out(), self.term_values());
        let TrackPass { tapes, terms, d, .. } = pass;
        let out = tapes.last().expect("forward ran").output();
        let d_out = d.last_mut().expect("sized by backward");
        d_out.resize(terms.len() / per_row * outs, 0.0);
        let rows = d_out
            .chunks_exact_mut(outs)
            .zip(terms.chunks_exact(per_row));
        let LightEntry::Combine { k } = self.light else {
            for (r, (d, e)) in rows.enumerate() {
                let f = &features[r * FEATURES..];
                self.kind.output_gradients(f, e, &dr[r * 3..r * 3 + 3], d);
            }
            return;
        };
        let mut d_terms = vec![0.0; per_row];
        for (r, (d, _)) in rows.enumerate() {
            let f = &features[r * FEATURES..];
            self.kind
                .term_gradients(f, &dr[r * 3..r * 3 + 3], &mut d_terms);
            let code = light.code(r, 3 * k);
            let at = light.view[r] as usize * 3 * k;
            let d_code = &mut d_codes[at..at + 3 * k];
            let t = &out[r * outs..(r + 1) * outs];
            for (i, (d, t)) in d.iter_mut().zip(t).enumerate() {
                // Output i is coefficient j of term `term`, channel c.
                let (term, j, c) = (i / (3 * k), (i / 3) % k, i % 3);
                let g = d_terms[term * 3 + c];
                *d = g * code[j * 3 + c];
                d_code[j * 3 + c] += g * t;
            }
        }
    }

    /// Backward of [`Self::forward`] from the gradient `upstream` at the radiance or the
    /// transfer vector, through the plan's steps in reverse: adds parameter gradients to
    /// `grads` and the gradient at each view's light code to `d_codes` (`views ×` the code's
    /// size).
    fn backward(
        &self,
        pass: &mut TrackPass,
        features: &[f32],
        light: Lighting,
        upstream: Upstream,
        grads: &mut Track,
        d_codes: &mut [f32],
    ) {
        let n = features.len() / FEATURES;
        let plan = self.plan();
        pass.d.resize_with(plan.steps.len(), Vec::new);
        // A linear track's code gradient comes from its outputs, at the combine.
        match upstream {
            Upstream::Radiance(dr) => self.d_outputs(pass, features, dr, light, d_codes),
            Upstream::Transfer(dt) => self.d_transfer_outputs(pass, features, dt),
        }
        let TrackPass {
            x, d_x, tapes, d, ..
        } = pass;
        // The gradient at the first step's inputs is needed only to train the grid.
        if self.grid.is_some() {
            d_x.resize(n * self.width(), 0.0);
        }
        for (i, step) in plan.steps.iter().enumerate().rev() {
            let (d_before, d_here) = d.split_at_mut(i);
            let (before, here) = tapes.split_at_mut(i);
            let (input, d_input) = match i {
                0 => (
                    self.gathered(features, x, n),
                    self.grid.as_ref().map(|_| d_x.as_mut_slice()),
                ),
                _ => {
                    let d = &mut d_before[i - 1];
                    d.resize(n * step.own_width, 0.0);
                    let input = MatRef::new(before[i - 1].output(), n, step.own_width);
                    (input, Some(d.as_mut_slice()))
                }
            };
            let shared = Self::shared(step, light);
            let d_shared = shared.as_ref().map(|_| &mut *d_codes);
            (self.mlp(step.net)).backward(
                input,
                shared.as_ref(),
                &mut here[0],
                &mut d_here[0],
                grads.mlp_mut(step.net),
                d_input,
                d_shared,
            );
        }
        self.grid_backward(features, d_x, grads);
    }
}

impl NprtNet {
    /// The batch's mean `loss` and its transport gradients, for the light codes `codes`
    /// (`views × code size`, the light model's output for the batch's maps).
    pub fn transport_gradients(
        &self,
        batch: &Samples,
        codes: &[f32],
        loss: Loss,
    ) -> TransportGradients {
        let n = batch.len();
        let views = codes.len() / self.light.code_size();
        let view: Vec<u32> = batch.view.iter().map(|&v| v as u32).collect();
        let blocks = n.div_ceil(BLOCK);
        let per_run = blocks.div_ceil(RUNS).max(1);
        let runs: Vec<TransportGradients> = (0..blocks.div_ceil(per_run))
            .into_par_iter()
            .map(|run| {
                let mut g = self.zero_gradients(views);
                with_passes(self.tracks.len(), |passes| {
                    for b in run * per_run..((run + 1) * per_run).min(blocks) {
                        let rows = b * BLOCK..((b + 1) * BLOCK).min(n);
                        let light = Lighting {
                            codes,
                            view: &view[rows.clone()],
                        };
                        self.block(batch, rows, light, loss, passes, &mut g);
                    }
                });
                g
            })
            .collect();
        let mut total = runs
            .into_iter()
            .reduce(|mut a, b| {
                a.loss += b.loss;
                accumulate(&mut a.codes, &b.codes);
                a.tracks
                    .iter_mut()
                    .zip(&b.tracks)
                    .for_each(|(x, y)| x.add(y));
                a
            })
            .unwrap_or_else(|| self.zero_gradients(views));
        total.loss /= (3 * n.max(1)) as f64;
        total
    }

    /// Multiply-adds × 2 per pixel of the dense layers and a linear track's dot products: all
    /// of them, or (`transfer_known`) only those a lighting change runs again. The light code's
    /// share of each shading network's first layer, made once per lighting, is not counted.
    pub fn flops_per_pixel(&self, transfer_known: bool) -> f64 {
        let dense = |s: &Mlp| -> f64 {
            s.layers
                .iter()
                .map(|l| 2.0 * (l.d_in * l.d_out) as f64)
                .sum()
        };
        self.tracks
            .iter()
            .map(|t| {
                let plan = t.plan();
                let steps = plan.steps.iter().enumerate();
                // A still camera's kept steps do not run again; a code's share of a first
                // layer is made once per lighting.
                let run = steps.filter(|(i, _)| !transfer_known || *i >= plan.kept);
                let networks: f64 = run
                    .map(|(_, s)| {
                        let m = t.mlp(s.net);
                        let code = s.code_rows.as_ref().map_or(0, |r| r.len());
                        dense(m) - 2.0 * (code * m.layers[0].d_out) as f64
                    })
                    .sum();
                // The dot products with the code where the light enters at the combine.
                let dots = match t.light.after_networks() {
                    true => 2.0 * plan.last().outputs as f64,
                    false => 0.0,
                };
                networks + dots
            })
            .sum()
    }

    /// Radiance (`n × 3`) of the rows of `features` lit by one light `code` of a map normalised
    /// by `scale`. With `known`, made by [`Self::kept_rows`] from the same features, what it
    /// keeps is not run again.
    pub fn radiance(
        &self,
        features: &[f32],
        code: &[f32],
        scale: [f32; 3],
        known: Option<&KeptRows>,
    ) -> Vec<f32> {
        assert_eq!(code.len(), self.light.code_size());
        self.shade(features, code, None, &|_| scale, known)
    }

    /// Radiance (`n × 3`) of a batch mixing views: each row lit by its view's code among
    /// `codes` (`views ×` the code's size) and scaled by its map's scale.
    pub fn predict(&self, batch: &Samples, codes: &[f32]) -> Vec<f32> {
        let view: Vec<u32> = batch.view.iter().map(|&v| v as u32).collect();
        let scale = |r: usize| std::array::from_fn(|i| batch.scale[3 * r + i]);
        self.shade(batch.features, codes, Some(&view), &scale, None)
    }

    /// The rows of `features` under `codes`, row r lit by code `view[r]` (the first code
    /// without `view`) and scaled by `scale(r)`.
    fn shade(
        &self,
        features: &[f32],
        codes: &[f32],
        view: Option<&[u32]>,
        scale: &(dyn Fn(usize) -> [f32; 3] + Sync),
        known: Option<&KeptRows>,
    ) -> Vec<f32> {
        let n = features.len() / FEATURES;
        let mut out = vec![0.0; n * 3];
        out.par_chunks_mut(BLOCK * 3)
            .zip(features.par_chunks(BLOCK * FEATURES))
            .enumerate()
            .for_each(|(b, (out, f))| {
                with_passes(self.tracks.len(), |passes| {
                    let rows = f.len() / FEATURES;
                    let light = Lighting {
                        codes,
                        view: view.map_or(&ONE_GROUP[..rows], |v| &v[b * BLOCK..][..rows]),
                    };
                    for (k, (t, pass)) in self.tracks.iter().zip(passes.iter_mut()).enumerate() {
                        let w = t.kept_width();
                        let s = known
                            .filter(|_| w > 0)
                            .map(|c| &c.tracks[k][b * BLOCK * w..][..rows * w]);
                        t.forward(f, light, rows, s, pass, Pass::Infer);
                        for r in 0..rows {
                            let c = t.radiance(pass, f, r);
                            (0..3).for_each(|i| out[r * 3 + i] += c[i]);
                        }
                    }
                    for (r, c) in out.chunks_exact_mut(3).enumerate() {
                        let s = scale(b * BLOCK + r);
                        (0..3).for_each(|i| c[i] *= s[i]);
                    }
                })
            });
        out
    }

    fn zero_gradients(&self, views: usize) -> TransportGradients {
        TransportGradients {
            loss: 0.0,
            tracks: self.tracks.iter().map(Track::zeros_like).collect(),
            codes: vec![0.0; views * self.light.code_size()],
        }
    }

    /// Adds the loss and gradients of the batch's rows `rows` to `g`.
    fn block(
        &self,
        batch: &Samples,
        rows: std::ops::Range<usize>,
        light: Lighting,
        loss: Loss,
        passes: &mut [TrackPass],
        g: &mut TransportGradients,
    ) {
        let n = rows.len();
        let features = &batch.features[rows.start * FEATURES..rows.end * FEATURES];
        let reference = &batch.radiance[rows.start * 3..rows.end * 3];
        let scale = &batch.scale[rows.start * 3..rows.end * 3];
        for (t, pass) in self.tracks.iter().zip(passes.iter_mut()) {
            t.forward(features, light, n, None, pass, Pass::Train);
        }
        if !batch.transfer.is_empty() {
            return self.transfer_block(batch, rows, light, passes, g);
        }
        // d mean / d value.
        let norm = 1.0 / batch.len() as f32 / 3.0;
        // Loss, and its gradient at each track's radiance (the same for every track).
        let mut dr = vec![0.0f32; n * 3];
        for r in 0..n {
            let mut p = [0.0f32; 3];
            for (t, pass) in self.tracks.iter().zip(passes.iter()) {
                let c = t.radiance(pass, features, r);
                (0..3).for_each(|i| p[i] += c[i]);
            }
            for c in 0..3 {
                let s = scale[r * 3 + c];
                let (value, slope) = loss.element(p[c] * s, reference[r * 3 + c]);
                g.loss += value as f64;
                dr[r * 3 + c] = slope * norm * s;
            }
        }
        let up = Upstream::Radiance(&dr);
        for ((t, pass), grads) in self.tracks.iter().zip(passes).zip(&mut g.tracks) {
            t.backward(pass, features, light, up, grads, &mut g.codes);
        }
    }
}
