//! A network's parameters as one flat device buffer (and its gradients and Adam's moments in
//! three more of the same layout), so that one dispatch updates them all. Each tensor starts at
//! a multiple of the device's storage-binding alignment, so a kernel can also bind one tensor
//! on its own; the gaps stay zero and Adam leaves them so.

use nprt_gpu::{GpuDevice, Span};

use crate::parameters::Parameters;

/// The flat layout of a network's tensors.
pub struct ParameterLayout {
    pub spans: Vec<Span>,
    /// Elements of the flat buffers, gaps included.
    pub total: usize,
}

impl ParameterLayout {
    /// The layout of `net`'s tensors (in their visiting order), each starting at a multiple
    /// of `gpu`'s storage-binding alignment (so a kernel can bind it on its own), and their
    /// values packed in it.
    pub fn pack_for<N: Parameters>(gpu: &GpuDevice, net: &N) -> (ParameterLayout, Vec<f32>) {
        Self::pack(net, gpu.binding_alignment())
    }

    /// [`Self::pack_for`] at an alignment of `align` elements.
    pub fn pack<N: Parameters>(net: &N, align: usize) -> (ParameterLayout, Vec<f32>) {
        let mut flat = Vec::new();
        let mut spans = Vec::new();
        net.visit("", &mut |_, _, t| {
            flat.resize(flat.len().next_multiple_of(align), 0.0);
            spans.push(Span {
                offset: flat.len(),
                len: t.len(),
            });
            flat.extend_from_slice(t);
        });
        let total = flat.len();
        (ParameterLayout { spans, total }, flat)
    }

    /// `flat`'s values poured into a copy of `net` (same shapes as packed).
    pub fn unpack<N: Parameters + Clone>(&self, flat: &[f32], net: &N) -> N {
        let mut net = net.clone();
        net.set_flat(&self.compact(flat));
        net
    }

    /// The tensors of `flat` one after the other, without the gaps: the host's layout
    /// ([`Parameters::flat`]).
    pub fn compact(&self, flat: &[f32]) -> Vec<f32> {
        (self.spans.iter())
            .flat_map(|s| flat[s.offset..][..s.len].iter().copied())
            .collect()
    }

    /// The inverse of [`Self::compact`]: the gaps zero.
    pub fn expand(&self, compact: &[f32]) -> Vec<f32> {
        let mut flat = vec![0.0; self.total];
        let mut at = 0;
        for s in &self.spans {
            flat[s.offset..][..s.len].copy_from_slice(&compact[at..at + s.len]);
            at += s.len;
        }
        flat
    }

    /// Values in the tensors, gaps not counted.
    pub fn params(&self) -> usize {
        self.spans.iter().map(|s| s.len).sum()
    }
}
