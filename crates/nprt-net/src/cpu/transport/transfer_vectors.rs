//! A linear track's transfer vectors on the CPU engine (training on `--transfer` datasets):
//! each row's vector, what the tracks' transfer coefficients weighted as their kinds weight
//! terms sum to, its squared error against the recorded one, and the gradient back at the
//! coefficients. The light code does not enter: the loss is lighting-free.

use super::{Lighting, TrackPass, TransportGradients, Upstream};
use crate::cpu::samples::Samples;
use crate::encoding::features::FEATURES;
use crate::network::light_entry::LightEntry;
use crate::network::nprt_net::NprtNet;
use crate::network::track::Track;

impl Track {
    /// Adds this linear track's part of row `r`'s transfer vector (K coefficients × RGB: what
    /// each coefficient's term values, weighted as the kind weights terms, sum to) to `out`.
    pub(super) fn add_transfer(
        &self,
        pass: &TrackPass,
        features: &[f32],
        r: usize,
        out: &mut [f32],
    ) {
        let (k, outs, per_row) = (self.linear(), self.shading.d_out(), self.term_values());
        let t = &pass.outputs()[r * outs..][..outs];
        let f = &features[r * FEATURES..];
        // Two terms at most (D/S's): the row's values stay on the stack.
        let mut e = [0.0; 6];
        let e = &mut e[..per_row];
        for (j, out) in out.chunks_exact_mut(3).enumerate().take(k) {
            // Output i is coefficient j of term `term`, channel c: i = term·3K + 3j + c.
            for (i, e) in e.iter_mut().enumerate() {
                *e = t[(i / 3) * 3 * k + 3 * j + i % 3];
            }
            let v = self.kind.radiance(f, e);
            out.iter_mut().zip(v).for_each(|(o, v)| *o += v);
        }
    }

    /// The gradient at a linear track's outputs (its last step's), from the gradient `dt` at
    /// each row's transfer vector (`rows × K × 3`).
    pub(super) fn d_transfer_outputs(&self, pass: &mut TrackPass, features: &[f32], dt: &[f32]) {
        let (k, outs, per_row) = (self.linear(), self.shading.d_out(), self.term_values());
        let rows = pass.terms.len() / per_row;
        let d_out = pass.d_outputs();
        d_out.resize(rows * outs, 0.0);
        let mut d_terms = vec![0.0; per_row];
        for (r, d) in d_out.chunks_exact_mut(outs).enumerate() {
            let f = &features[r * FEATURES..];
            for j in 0..k {
                self.kind
                    .term_gradients(f, &dt[(r * k + j) * 3..][..3], &mut d_terms);
                for (i, g) in d_terms.iter().enumerate() {
                    d[(i / 3) * 3 * k + 3 * j + i % 3] = *g;
                }
            }
        }
    }

    /// The coefficients per channel of a linear track (only a linear track has transfer
    /// vectors to learn: training checks it before the first step).
    fn linear(&self) -> usize {
        match self.light {
            LightEntry::Combine { k } => k,
            LightEntry::FirstLayer { .. } => {
                panic!("transfer vectors are learned by the linear design's tracks")
            }
        }
    }
}

impl NprtNet {
    /// [`Self::block`] on transfer vectors, its tracks run forward: the squared error of each
    /// coefficient (counted 1/K, so the batch's loss is their mean), lighting-free.
    pub(super) fn transfer_block(
        &self,
        batch: &Samples,
        rows: std::ops::Range<usize>,
        light: Lighting,
        passes: &mut [TrackPass],
        g: &mut TransportGradients,
    ) {
        let features = &batch.features[rows.start * FEATURES..rows.end * FEATURES];
        let per_row = batch.transfer.len() / batch.len();
        let reference = &batch.transfer[rows.start * per_row..rows.end * per_row];
        let norm = 1.0 / (batch.len() * per_row) as f32;
        let k = per_row as f64 / 3.0;
        let mut dt = vec![0.0f32; reference.len()];
        for (r, (dt, want)) in dt
            .chunks_exact_mut(per_row)
            .zip(reference.chunks_exact(per_row))
            .enumerate()
        {
            for (t, pass) in self.tracks.iter().zip(passes.iter()) {
                t.add_transfer(pass, features, r, dt);
            }
            for (d, want) in dt.iter_mut().zip(want) {
                let e = *d - want;
                g.loss += (e * e) as f64 / k;
                *d = 2.0 * e * norm;
            }
        }
        let up = Upstream::Transfer(&dt);
        for ((t, pass), grads) in self.tracks.iter().zip(passes).zip(&mut g.tracks) {
            t.backward(pass, features, light, up, grads, &mut g.codes);
        }
    }
}
