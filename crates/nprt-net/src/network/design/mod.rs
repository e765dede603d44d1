//! The transport designs: the paper's four (its Table 1) and the linear designs beyond them. One file per
//! design states everything that is its own ([`DesignSpec`]): its tracks, its networks' sizes,
//! its default activation, the paper's parameter count and the measured learning rate; the
//! networks, the engines and the training recipe read it from there.

mod albedo;
mod baseline;
mod dsep;
mod linear;
mod linear_diffuse;
mod linear_direct;
mod prt;

use crate::choice::named_choice;
use crate::network::activation::Activation;
use crate::network::encoder::CODE_SIZE;
use crate::network::light_entry::LightEntry;
use crate::network::track_kind::TrackKind;

/// Size of the transport code ŝ.
pub const TRANSPORT_CODE: usize = 64;

/// How a design's tracks turn pixel inputs and the light code into outputs.
pub enum Layout {
    /// One MLP on [ê, inputs] with these hidden widths.
    Direct { hidden: &'static [usize] },
    /// A transfer network F_T(inputs) → ŝ and a shading network Φ(ŝ, ê), both two hidden
    /// layers of `width` (F_T with the design's activation, Φ with ReLU).
    Transfer { width: usize },
}

/// Where a track's light code enters it, as a design states it ([`LightEntry`] adds the rows).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Enters {
    /// Φ's first layer reads the code beside its per-row input (the paper's).
    FirstLayer,
    /// Φ reads its per-row input alone and outputs K transfer coefficients per term and
    /// channel, dotted with the code at the combine: the track is linear in the lighting.
    Combine,
}

/// What makes a design's light code, and where the code enters each track.
pub enum LightPlan {
    /// The paper's convolutional encoder F_L; its code ê enters every track's Φ at its first
    /// layer.
    Encoder,
    /// The map's projection e = P·E on a basis of K functions per colour channel (`--basis`);
    /// it enters each track, in `tracks`' order, as listed.
    Basis(&'static [Enters]),
}

/// One design, as its file states it.
pub struct DesignSpec {
    pub name: &'static str,
    /// Its tracks, each with networks of its own; radiance is their sum.
    pub tracks: &'static [TrackKind],
    pub layout: Layout,
    /// The activation of the layers that see the pixel inputs, unless asked otherwise.
    pub default_activation: Activation,
    /// Transport parameters the paper gives (Table 1); 0 for a design beyond the paper.
    pub paper_params: usize,
    /// The peak learning rate measured best under the cosine schedule (`recipe_rate`).
    pub cosine_rate: f64,
    /// Its light code and where it enters each track.
    pub light: LightPlan,
}

/// The transport design (the paper's Table 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Design {
    /// One MLP on [ê, inputs]: 83 → 256 ×4 → 3.
    Baseline,
    /// PRT-inspired: F_T(inputs) = ŝ, then Φ(ŝ, ê) → radiance.
    Prt,
    /// As PRT, but Φ outputs L^D and L^S and L = kd·L^D + ks·L^S.
    Albedo,
    /// Two tracks of width 172: diffuse F_T^D(x, n, kd) and specular F_T^S(x, n, ks, ωo, ωr, α),
    /// each with its own Φ; L = kd·Φ^D + ks·Φ^S.
    Dsep,
    /// Beyond the paper: D/S's tracks, each Φ(ŝ) a transfer matrix dotted with the map's
    /// projection on a basis; exact under any gain or mixture of maps.
    Linear,
    /// Beyond the paper: the linear design with one MLP per track from the inputs to the
    /// transfer matrix (no ŝ).
    LinearDirect,
    /// Beyond the paper: D/S's tracks on the basis projection, the diffuse one linear in the
    /// lighting (as the linear design's), the specular one's Φ reading the projection through
    /// its first layer (as the paper's Φ reads ê).
    LinearDiffuse,
}

named_choice!(Design, "design", {
    Baseline => "baseline",
    Prt => "prt",
    Albedo => "albedo",
    Dsep => "dsep",
    Linear => "linear",
    LinearDirect => "linear-direct",
    LinearDiffuse => "linear-diffuse",
});

impl Design {
    /// The paper's four designs, in its Tables 1 and 5's order: what its tables compare (a
    /// design beyond the paper is in [`Design::ALL`], not here).
    pub const PAPER: [Design; 4] = [Design::Baseline, Design::Prt, Design::Albedo, Design::Dsep];

    pub fn spec(self) -> &'static DesignSpec {
        match self {
            Design::Baseline => &baseline::SPEC,
            Design::Prt => &prt::SPEC,
            Design::Albedo => &albedo::SPEC,
            Design::Dsep => &dsep::SPEC,
            Design::Linear => &linear::SPEC,
            Design::LinearDirect => &linear_direct::SPEC,
            Design::LinearDiffuse => &linear_diffuse::SPEC,
        }
    }

    /// Transport parameter count the paper gives (Table 1).
    pub fn paper_params(self) -> usize {
        self.spec().paper_params
    }

    /// The paper's activation for the layers that see the pixel inputs: ReLU for the baseline,
    /// SIREN for the transport networks F_T of the other designs.
    pub fn default_activation(self) -> Activation {
        self.spec().default_activation
    }

    /// Whether the light code is the map's projection on a basis (`--basis`) rather than the
    /// encoder's.
    pub fn reads_basis(self) -> bool {
        matches!(self.spec().light, LightPlan::Basis(_))
    }

    /// Whether every track is linear in the lighting (its code enters at the combine): what
    /// learning transfer vectors (`--targets transfer`) needs.
    pub fn linear_in_light(self) -> bool {
        match self.spec().light {
            LightPlan::Encoder => false,
            LightPlan::Basis(enters) => enters.iter().all(|e| *e == Enters::Combine),
        }
    }

    /// Each track's light entry, in `tracks`' order, for a basis of `basis_size` functions per
    /// channel (ignored with the encoder).
    pub fn entries(self, basis_size: usize) -> Vec<LightEntry> {
        let spec = self.spec();
        let own = self.has_transfer().then_some(TRANSPORT_CODE);
        let first_layer = |code_size| LightEntry::first_layer(own, code_size);
        match spec.light {
            LightPlan::Encoder => vec![first_layer(CODE_SIZE); spec.tracks.len()],
            LightPlan::Basis(enters) => enters
                .iter()
                .map(|e| match e {
                    Enters::FirstLayer => first_layer(3 * basis_size),
                    Enters::Combine => LightEntry::Combine { k: basis_size },
                })
                .collect(),
        }
    }

    /// Whether the design splits transport from shading (a still camera then keeps ŝ).
    pub fn has_transfer(self) -> bool {
        matches!(self.spec().layout, Layout::Transfer { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_design_file_names_its_design() {
        for d in Design::ALL {
            assert_eq!(d.spec().name, d.name());
        }
    }

    #[test]
    fn a_basis_plan_names_an_entry_for_each_track() {
        for d in Design::ALL {
            assert_eq!(d.entries(9).len(), d.spec().tracks.len(), "{d}");
        }
    }

    #[test]
    fn the_papers_designs_are_those_with_the_papers_counts() {
        let paper: Vec<Design> = Design::ALL
            .into_iter()
            .filter(|d| d.paper_params() > 0)
            .collect();
        assert_eq!(paper, Design::PAPER);
    }
}
