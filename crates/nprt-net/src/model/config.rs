//! Everything needed to rebuild a network besides its weights, and the defaults of the choices
//! beyond the paper's design.

use serde::{Deserialize, Serialize};

use crate::encoding::map_norm::MapNorm;
use crate::encoding::position_encoding::PositionEncoding;
use nprt_scene::EnvMap;

use crate::init::Init;
use crate::model::direct_light::DirectLight;
use crate::network::activation::Activation;
use crate::network::design::Design;
use crate::network::encoder::{LightInput, Texels};
use crate::network::light_basis::BasisChoice;
use crate::network::nprt_net::NprtNet;

/// Everything needed to rebuild a network, besides its weights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelConfig {
    pub design: Design,
    pub activation: Activation,
    /// Width W of the encoder's W × W/2 input map.
    pub encoder_width: usize,
    /// How the map is normalised for the encoder (absent in older files: the paper's mean).
    #[serde(default)]
    pub map_norm: MapNorm,
    /// Whether the network predicts direct light or leaves it to the tracer (absent in older
    /// files: learned, as in the paper). Written only when traced, so that a learned model's
    /// file and run key stay what they were and its unfinished runs still resume.
    #[serde(default, skip_serializing_if = "DirectLight::is_learned")]
    pub direct: DirectLight,
    /// How the transport network sees the position (absent in older files: as the paper
    /// does). Written only for a hash grid, for the same reason as `direct`.
    #[serde(default, skip_serializing_if = "PositionEncoding::is_none")]
    pub encoding: PositionEncoding,
    /// The linear designs' light basis (absent: [`BasisChoice::default`]); written only for
    /// them, which alone read it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub basis: Option<BasisChoice>,
}

/// Copies of a network's floats a training run holds: the weights, their gradient, Adam's two
/// moments and an engine's working copies (measured: 12.8 GB for a 2.1 GB learned basis).
pub const TRAINING_COPIES: u128 = 6;

/// Encoder input width when none is asked for: on the demo, 64 measured 10% worse in L1 than
/// 128 for 10% less training time.
pub const DEFAULT_ENCODER_WIDTH: usize = 128;

/// Map normalisation when none is asked for: per channel, better than the paper's single mean in
/// every error measured on held-out maps, though not yet in their colour balance (docs/model.md).
pub const DEFAULT_MAP_NORM: MapNorm = MapNorm::Channel;

impl ModelConfig {
    pub fn new(design: Design, activation: Option<Activation>) -> Self {
        ModelConfig {
            design,
            activation: activation.unwrap_or(design.default_activation()),
            encoder_width: DEFAULT_ENCODER_WIDTH,
            map_norm: DEFAULT_MAP_NORM,
            direct: DirectLight::Learned,
            encoding: PositionEncoding::None,
            basis: design.reads_basis().then(BasisChoice::default),
        }
    }

    /// Refuses a basis given to a design that has none.
    pub fn check(&self) -> anyhow::Result<()> {
        if let (Some(b), false) = (self.basis, self.design.reads_basis()) {
            let on_a_basis: Vec<&str> = (Design::ALL.into_iter())
                .filter(|d| d.reads_basis())
                .map(Design::name)
                .collect();
            anyhow::bail!(
                "light basis {b} given to design {}: only the linear designs ({}) project the \
                 lighting on a basis",
                self.design,
                on_a_basis.join(", ")
            );
        }
        Ok(())
    }

    /// The linear design's basis (its default where the file names none).
    pub fn light_basis(&self) -> BasisChoice {
        self.basis.unwrap_or_default()
    }

    /// The basis this model's light model projects maps on; None for a design with the
    /// encoder.
    pub fn basis_in_use(&self) -> Option<BasisChoice> {
        self.design.reads_basis().then(|| self.light_basis())
    }

    /// The SH band whose transfer vectors this model can learn (`--targets transfer`): its
    /// basis' band where the basis is SH and every track is linear in the lighting; None
    /// otherwise.
    pub fn transfer_band(&self) -> Option<usize> {
        match (self.design.linear_in_light(), self.light_basis()) {
            (true, BasisChoice::Sh { band }) => Some(band),
            _ => None,
        }
    }

    /// How this model's light model takes a map's texels: as they are for the linear design's
    /// basis, through log(1 + x) for the encoder.
    pub fn texels(&self) -> Texels {
        match self.basis_in_use() {
            Some(_) => Texels::Linear,
            None => Texels::Log,
        }
    }

    /// `map` turned by `rotation_deg` about +Y as this model's light model takes it.
    pub fn light_input(&self, map: &EnvMap, rotation_deg: f32) -> LightInput {
        let (width, norm) = (self.encoder_width, self.map_norm);
        LightInput::with_texels(map, rotation_deg, width, norm, self.texels())
    }

    /// The design's name, marked `+siren` or `+relu` with an activation other than the paper's
    /// for it (Table 2's ablation), `+grid` with a hash grid and `+direct` when direct light is
    /// traced: how reports name it.
    pub fn label(&self) -> String {
        let activation = if self.activation == self.design.default_activation() {
            String::new()
        } else {
            format!("+{}", self.activation)
        };
        let grid = match self.encoding {
            PositionEncoding::None => "",
            PositionEncoding::HashGrid => "+grid",
        };
        let direct = match self.direct {
            DirectLight::Learned => "",
            DirectLight::Traced => "+direct",
        };
        let basis = (self.basis_in_use()).map_or(String::new(), |b| format!("+{b}"));
        format!("{}{basis}{activation}{grid}{direct}", self.design.name())
    }

    /// What the model is, for the one line each command prints of what it runs: "linear
    /// design on sh:2 (siren), direct light traced".
    pub fn describe(&self) -> String {
        let basis = (self.basis_in_use()).map_or(String::new(), |b| format!(" on {b}"));
        let grid = match self.encoding {
            PositionEncoding::None => "",
            PositionEncoding::HashGrid => ", hash grid",
        };
        format!(
            "{} design{basis} ({}{grid}), direct light {}",
            self.design, self.activation, self.direct
        )
    }

    /// What the weights file records of the network that wrote it: the design and the
    /// activation, which both change what the same weights compute (an edit of model.json's
    /// activation went undetected).
    pub fn weights_tag(&self) -> String {
        match self.basis_in_use() {
            Some(b) => format!("{}:{}:{b}", self.design, self.activation),
            None => format!("{}:{}", self.design.name(), self.activation),
        }
    }

    /// An upper bound on the floats the network holds: the linear design's basis (K functions at
    /// each of the W × W/2 texels: 537 M at learned:1024 and width 1024) dominates where it is
    /// large; the rest stays under 16 M at any width (the encoder's W² dense layer, the MLPs, a
    /// hash grid).
    pub fn floats_bound(&self) -> u128 {
        let w = self.encoder_width as u128;
        let basis = (self.basis_in_use()).map_or(0, |b| b.size() as u128 * w * w / 2);
        basis + (16 << 20)
    }

    /// Refuses a network whose `copies` of its floats (1 to render; a training run's weights,
    /// gradients, Adam's two moments and the engine's copies: [`TRAINING_COPIES`]) would not fit
    /// in the available memory, naming its size: `--basis learned:1024 --encoder-width 1024`
    /// took 12.8 GB and aborted under a memory limit.
    pub fn ensure_memory(&self, copies: u128, what: &str) -> anyhow::Result<()> {
        let basis = (self.basis_in_use()).map_or(String::new(), |b| {
            format!(" (basis {b} at encoder width {})", self.encoder_width)
        });
        nprt_io::ensure_memory(
            self.floats_bound() * 4 * copies,
            &format!(
                "{what}{basis}, {copies} cop{} of its weights,",
                match copies {
                    1 => "y",
                    _ => "ies",
                }
            ),
        )
    }

    pub fn build(&self, init: &mut Init) -> NprtNet {
        NprtNet::new(
            init,
            self.design,
            self.activation,
            self.encoder_width,
            self.encoding,
            self.light_basis(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A network's memory is bounded before it is built: a learned:1024 basis at width 1024 is
    /// 537 M floats (it held 12.8 GB in training and aborted under a memory limit).
    #[test]
    fn a_network_beyond_memory_is_refused_naming_its_basis_and_width() {
        let mut config = ModelConfig::new(Design::Linear, None);
        config.encoder_width = 1024;
        config.basis = Some("learned:1024".parse().unwrap());
        assert!(config.floats_bound() >= 1024 * 1024 * 512);
        let err = config
            .ensure_memory(1 << 40, "training the network")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("training the network (basis learned:1024 at encoder width 1024)"),
            "{err}"
        );
        // The bound holds every design's network at the default width.
        for design in Design::ALL {
            let config = ModelConfig::new(design, None);
            let net = config.build(&mut Init::new(0));
            assert!(
                net.total_params() as u128 <= config.floats_bound(),
                "{design}"
            );
        }
        ModelConfig::new(Design::Dsep, None)
            .ensure_memory(1, "a network")
            .unwrap();
    }

    #[test]
    fn older_configs_read_as_the_paper_s_and_learned_ones_keep_their_old_form() {
        let old = r#"{"design": "dsep", "activation": "siren", "encoder_width": 128}"#;
        let config: ModelConfig = serde_json::from_str(old).unwrap();
        assert_eq!(config.map_norm, MapNorm::Mean);
        assert_eq!(config.direct, DirectLight::Learned);
        // A learned model's config (and so its run key) has no `direct` field, as before the
        // choice existed; a traced one has it and reads back.
        let json = serde_json::to_value(&config).unwrap();
        assert!(json.get("direct").is_none(), "{json}");
        let traced = ModelConfig {
            direct: DirectLight::Traced,
            ..config
        };
        let json = serde_json::to_string(&traced).unwrap();
        assert!(json.contains(r#""direct":"traced""#), "{json}");
        assert_eq!(serde_json::from_str::<ModelConfig>(&json).unwrap(), traced);
        assert_eq!(traced.label(), "dsep+direct");
        assert!(!json.contains("encoding"), "{json}");
        let grid = ModelConfig {
            encoding: PositionEncoding::HashGrid,
            ..traced
        };
        let json = serde_json::to_string(&grid).unwrap();
        assert!(json.contains(r#""encoding":"hash-grid""#), "{json}");
        assert_eq!(serde_json::from_str::<ModelConfig>(&json).unwrap(), grid);
        assert_eq!(grid.label(), "dsep+grid+direct");
        assert_eq!(
            grid.describe(),
            "dsep design (siren, hash grid), direct light traced"
        );
    }
}
