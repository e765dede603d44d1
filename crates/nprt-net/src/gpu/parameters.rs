//! A network's parameters as one flat device buffer (and its gradients and Adam's moments in
//! three more of the same layout), so that one dispatch updates them all. Each tensor starts at
//! a multiple of the device's storage-binding alignment, so a kernel can also bind one tensor
//! on its own; the gaps stay zero and Adam leaves them so.

use crate::cpu::{HostEncoder, HostTransport};

/// Where one tensor lies in the flat buffers, in f32 elements.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    pub offset: usize,
    pub len: usize,
}

impl Span {
    /// The byte range, for binding this tensor alone.
    pub fn bytes(self) -> (u64, u64) {
        ((self.offset * 4) as u64, (self.len * 4) as u64)
    }
}

/// Every tensor of a network in its one order: the encoder's convolutions (weight, bias), its
/// last layer, then per track the grid's tables, the transfer network's layers and the shading
/// network's layers. Packing and unpacking both walk it.
fn tensors<'a>(
    encoder: &'a mut HostEncoder,
    transport: &'a mut HostTransport,
) -> Vec<&'a mut Vec<f32>> {
    let mut all = Vec::new();
    for conv in &mut encoder.convs {
        all.push(&mut conv.weight);
        all.push(&mut conv.bias);
    }
    all.push(&mut encoder.to_code.weight);
    all.push(&mut encoder.to_code.bias);
    for track in &mut transport.tracks {
        if let Some(grid) = &mut track.grid {
            all.push(grid);
        }
        let layers = track.transfer.iter_mut().flat_map(|t| t.layers.iter_mut());
        for layer in layers.chain(track.shading.layers.iter_mut()) {
            all.push(&mut layer.weight);
            all.push(&mut layer.bias);
        }
    }
    all
}

/// The flat layout of a network's tensors.
pub struct ParameterLayout {
    pub spans: Vec<Span>,
    /// Elements of the flat buffers, gaps included.
    pub total: usize,
}

impl ParameterLayout {
    /// The layout of `encoder` and `transport` with tensors starting at multiples of `align`
    /// elements, and their values packed in it.
    pub fn pack(
        encoder: &HostEncoder,
        transport: &HostTransport,
        align: usize,
    ) -> (ParameterLayout, Vec<f32>) {
        let (mut encoder, mut transport) = (encoder.clone(), transport.clone());
        let mut flat = Vec::new();
        let mut spans = Vec::new();
        for t in tensors(&mut encoder, &mut transport) {
            flat.resize(flat.len().next_multiple_of(align), 0.0);
            spans.push(Span {
                offset: flat.len(),
                len: t.len(),
            });
            flat.extend_from_slice(t);
        }
        let total = flat.len();
        (ParameterLayout { spans, total }, flat)
    }

    /// `flat`'s values poured into copies of `encoder` and `transport` (same shapes as packed).
    pub fn unpack(
        &self,
        flat: &[f32],
        encoder: &HostEncoder,
        transport: &HostTransport,
    ) -> (HostEncoder, HostTransport) {
        let (mut encoder, mut transport) = (encoder.clone(), transport.clone());
        for (t, span) in tensors(&mut encoder, &mut transport)
            .into_iter()
            .zip(&self.spans)
        {
            t.copy_from_slice(&flat[span.offset..][..span.len]);
        }
        (encoder, transport)
    }
}
