//! The linear design's basis on the device: its functions (fixed, or a learned tensor of the
//! flat parameters) and each texel's solid angle, and the dispatches that project a batch's
//! maps on it (`light_project`) and take a learned basis' gradient (`light_project_backward`),
//! what `cpu::light_model` computes on the host.

use crate::gpu::kernels::{LIGHT_PROJECT, LIGHT_PROJECT_BACKWARD};
use crate::network::light_basis::LightBasis;
use nprt_gpu::{groups_for, Bind, Dispatch, GpuDevice, Part, Span};

/// Where a basis' functions lie.
pub enum BasisFunctions {
    /// Spherical harmonics: uploaded once.
    Fixed(wgpu::Buffer),
    /// Trained with the network: its tensor in the flat parameters (and gradients).
    Learned(Span),
}

/// A basis of `size` functions over maps of `texels` texels.
pub struct BasisAt {
    pub size: usize,
    pub texels: usize,
    /// Each texel's solid angle.
    solid: wgpu::Buffer,
    pub functions: BasisFunctions,
}

impl BasisAt {
    /// `basis` on `gpu`, a learned one's span taken from `spans` (its visiting order).
    pub fn new(
        gpu: &GpuDevice,
        basis: &LightBasis,
        spans: &mut impl Iterator<Item = Span>,
    ) -> Self {
        let solid = basis.texel_solid_angles();
        let functions = match basis.choice.is_learned() {
            true => BasisFunctions::Learned(spans.next().expect("a learned basis' span")),
            false => BasisFunctions::Fixed(gpu.upload(&basis.functions)),
        };
        BasisAt {
            size: basis.size(),
            texels: solid.len(),
            solid: gpu.upload(&solid),
            functions,
        }
    }

    /// The codes (`views × 3K`) of the `views` inputs in `pixels` (each 3 × texels), the
    /// functions read from `params` where they are learned.
    pub fn record_project(
        &self,
        gpu: &GpuDevice,
        params: &wgpu::Buffer,
        pixels: &wgpu::Buffer,
        views: usize,
        codes: &wgpu::Buffer,
    ) -> Dispatch {
        let part;
        let functions: &dyn Bind = match &self.functions {
            BasisFunctions::Fixed(f) => f,
            BasisFunctions::Learned(span) => {
                part = Part {
                    buffer: params,
                    span: *span,
                };
                &part
            }
        };
        gpu.prepare(
            &LIGHT_PROJECT,
            &[self.size, self.texels, views, 0].map(|v| v as u32),
            &[functions, &self.solid, pixels, codes],
            groups_for(views * 3 * self.size),
        )
    }

    /// A learned basis' gradient into `grads` from the gradient at the codes of the inputs in
    /// `pixels`; none for a fixed basis.
    pub fn record_backward(
        &self,
        gpu: &GpuDevice,
        grads: &wgpu::Buffer,
        pixels: &wgpu::Buffer,
        views: usize,
        d_codes: &wgpu::Buffer,
    ) -> Option<Dispatch> {
        let BasisFunctions::Learned(span) = self.functions else {
            return None;
        };
        let out = Part {
            buffer: grads,
            span,
        };
        Some(gpu.prepare(
            &LIGHT_PROJECT_BACKWARD,
            &[self.size, self.texels, views, 0].map(|v| v as u32),
            &[&self.solid, pixels, d_codes, &out],
            groups_for(self.size * self.texels),
        ))
    }
}
