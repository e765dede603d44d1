//! Who supplies a model's direct light: its network (the paper) or the tracer at run time.

use nprt_data::dataset::PackedTarget;

use crate::choice::named_choice;

/// Where the direct light of a relit frame comes from (the map seen directly and light that
/// reached the first surface straight from it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DirectLight {
    /// The network predicts all the radiance (the paper). Models saved before the choice
    /// existed were trained this way.
    #[default]
    Learned,
    /// A few rays per pixel trace it at run time (shadow rays towards the importance-sampled
    /// map, and one BSDF sample), and the network learns only the rest: the paper's suggestion
    /// in its limitations section. Sharp shadows and sun patches, which a small network places
    /// poorly under a never-seen lighting, come from the tracer; the indirect light left to the
    /// network is smooth.
    Traced,
}

named_choice!(DirectLight, "direct light", {
    Learned => "learned",
    Traced => "traced",
});

impl DirectLight {
    pub fn is_learned(&self) -> bool {
        *self == DirectLight::Learned
    }

    /// What the network learns of a pixel: all its radiance, or the indirect part. Reference
    /// and direct part come from the same paths, so their difference is an estimate of the
    /// indirect light that is never negative but for rounding.
    pub fn packed_target(self) -> PackedTarget {
        match self {
            DirectLight::Learned => PackedTarget::Radiance,
            DirectLight::Traced => PackedTarget::Indirect,
        }
    }
}
