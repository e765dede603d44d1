//! The recommended recipe: nprt's measured best relighting, stated once (a design, from
//! `network::design`, with every choice of its dataset, training and run time). `nprt train`
//! trains it when no `--arch` is given, `nprt generate` records the dataset it needs without
//! expert flags, `nprt bake` runs it end to end, and run time (render, view, eval, export)
//! traces and denoises its direct light as the model records it. The paper's designs stay one flag away (`--arch`),
//! with the paper's own settings. docs/model.md ("The recommended recipe") has the measurements
//! that chose each part.

use anyhow::Result;
use nprt_data::dataset::TransferBasis;
use nprt_trace::TraceDevice;

use crate::model::config::ModelConfig;
use crate::model::direct_light::DirectLight;
use crate::network::activation::Activation;
use crate::network::design::Design;
use crate::network::light_basis::BasisChoice;
use crate::training::calibration::Calibration;
use crate::training::train_options::Targets;

/// Every choice of one way to make and run a model, beyond the network's layers (which its
/// design states).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Recipe {
    pub design: Design,
    /// The light basis of a linear design.
    pub basis: Option<BasisChoice>,
    /// Who supplies the direct light: the network, or rays traced at run time.
    pub direct: DirectLight,
    /// Samples per pixel of that light when it is traced.
    pub direct_spp: u32,
    /// Whether run time denoises the traced light with Open Image Denoise where it is
    /// installed (the G-buffer's albedo and normal guiding it), unless a check of the model on
    /// held-out views measured it better raw (nprt-render's `Denoise`).
    pub denoise_direct: bool,
    /// How the saved model's level is set.
    pub calibration: Calibration,
    /// Train on the transfer vectors where the dataset recorded them for the model's basis, on
    /// radiance elsewhere.
    pub transfer_targets: bool,
    /// The transfer vectors `nprt generate` records by default (none: radiance only).
    pub dataset_transfer: Option<TransferBasis>,
}

/// The recommended recipe: the linear design on spherical harmonics to band 2, its direct light
/// traced at 16 stratified samples a pixel and denoised where that measures better, its level
/// calibrated, trained on transfer vectors where the dataset has them and on radiance otherwise
/// (the two tie at minutes of training, and recording the vectors costs half the training
/// views' time again, so `nprt generate` records none by default). docs/model.md, "The
/// recommended recipe".
pub const RECIPE: Recipe = Recipe {
    design: Design::Linear,
    basis: Some(BasisChoice::Sh { band: 2 }),
    direct: DirectLight::Traced,
    direct_spp: 16,
    denoise_direct: true,
    calibration: Calibration::Level,
    transfer_targets: true,
    dataset_transfer: None,
};

impl Recipe {
    /// The model this recipe trains.
    pub fn config(&self) -> ModelConfig {
        ModelConfig {
            direct: self.direct,
            basis: self.basis,
            ..ModelConfig::new(self.design, None)
        }
    }

    /// The transfer vectors a dataset traced on `device` records when none are asked for: the
    /// recipe's, which the CPU tracer alone records (a GPU-traced dataset has none, and the
    /// recipe then trains on its radiance).
    pub fn dataset_transfer_on(&self, device: TraceDevice) -> Option<TransferBasis> {
        self.dataset_transfer.filter(|_| device.is_cpu())
    }

    /// What a model of `config` learns on a dataset whose transfer vectors are `recorded`: the
    /// vectors where the recipe takes them and they hold the model's basis, else radiance.
    pub fn targets(&self, config: &ModelConfig, recorded: Option<TransferBasis>) -> Targets {
        let holds = match (config.transfer_band(), recorded) {
            (Some(band), Some(t)) => t.band as usize >= band,
            _ => false,
        };
        match self.transfer_targets && holds {
            true => Targets::Transfer,
            false => Targets::Radiance,
        }
    }
}

/// What a training run was asked, each choice None where it was not given: the design (none:
/// the recommended recipe) and the choices that the recipe, or else the named design's own
/// defaults (the paper's, for the paper's designs), make otherwise. `nprt train` and Python's
/// `nprt.train` resolve their arguments here.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Asked {
    pub design: Option<Design>,
    pub activation: Option<Activation>,
    pub direct: Option<DirectLight>,
    pub basis: Option<BasisChoice>,
    pub calibration: Option<Calibration>,
    pub targets: Option<Targets>,
}

impl Asked {
    /// The recipe this run follows: [`RECIPE`] where no design was named.
    pub fn recipe(&self) -> Option<Recipe> {
        self.design.is_none().then_some(RECIPE)
    }

    /// The model: the recipe's or the named design's, with each choice given applied (and
    /// refused where the design has no use for it).
    pub fn config(&self) -> Result<ModelConfig> {
        let base = match self.design {
            Some(design) => ModelConfig::new(design, self.activation),
            None => ModelConfig {
                activation: (self.activation).unwrap_or(RECIPE.design.default_activation()),
                ..RECIPE.config()
            },
        };
        let config = ModelConfig {
            direct: self.direct.unwrap_or(base.direct),
            basis: self.basis.or(base.basis),
            ..base
        };
        config.check()?;
        Ok(config)
    }

    /// How the saved model's level is set: as asked, else the recipe's, else none (the paper).
    pub fn calibration(&self) -> Calibration {
        let recipe = self.recipe().map(|r| r.calibration);
        self.calibration.or(recipe).unwrap_or_default()
    }

    /// What `config` learns on a dataset whose transfer vectors are `recorded`: as asked, else
    /// the recipe's choice for that dataset, else radiance (the paper).
    pub fn targets(&self, config: &ModelConfig, recorded: Option<TransferBasis>) -> Targets {
        let recipe = self.recipe().map(|r| r.targets(config, recorded));
        self.targets.or(recipe).unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_recipe_trains_on_transfer_vectors_only_where_they_hold_its_basis() {
        let config = RECIPE.config();
        assert_eq!(config.label(), "linear+sh:2+direct");
        assert!(config.check().is_ok());
        let recorded = |band| Some(TransferBasis { band });
        let on_vectors = Recipe {
            transfer_targets: true,
            ..RECIPE
        };
        assert_eq!(on_vectors.targets(&config, recorded(2)), Targets::Transfer);
        assert_eq!(on_vectors.targets(&config, recorded(4)), Targets::Transfer);
        assert_eq!(on_vectors.targets(&config, recorded(1)), Targets::Radiance);
        assert_eq!(on_vectors.targets(&config, None), Targets::Radiance);
        // A design without coefficients to learn, even on a dataset with vectors.
        let dsep = ModelConfig::new(Design::Dsep, None);
        assert_eq!(on_vectors.targets(&dsep, recorded(2)), Targets::Radiance);
        let on_radiance = Recipe {
            transfer_targets: false,
            ..RECIPE
        };
        assert_eq!(on_radiance.targets(&config, recorded(2)), Targets::Radiance);
        // What the recipe trains on the dataset `nprt generate` makes by default: its vectors
        // where it records them, else radiance.
        let expected = match RECIPE.dataset_transfer {
            Some(_) if RECIPE.transfer_targets => Targets::Transfer,
            _ => Targets::Radiance,
        };
        assert_eq!(RECIPE.targets(&config, RECIPE.dataset_transfer), expected);
    }

    #[test]
    fn a_named_design_keeps_its_own_defaults_and_the_recipe_takes_each_choice_given() {
        let recipe = Asked::default();
        assert_eq!(recipe.config().unwrap(), RECIPE.config());
        assert_eq!(recipe.calibration(), RECIPE.calibration);
        let vectors = Some(TransferBasis { band: 2 });
        let config = recipe.config().unwrap();
        assert_eq!(
            recipe.targets(&config, vectors),
            RECIPE.targets(&config, vectors)
        );
        // The paper's design as the paper trains it, the recipe notwithstanding.
        let dsep = Asked {
            design: Some(Design::Dsep),
            ..Asked::default()
        };
        assert_eq!(dsep.config().unwrap(), ModelConfig::new(Design::Dsep, None));
        assert_eq!(dsep.calibration(), Calibration::None);
        let config = dsep.config().unwrap();
        assert_eq!(dsep.targets(&config, vectors), Targets::Radiance);
        // The recipe with one choice changed.
        let learned = Asked {
            direct: Some(DirectLight::Learned),
            basis: Some(BasisChoice::Sh { band: 4 }),
            calibration: Some(Calibration::None),
            ..Asked::default()
        };
        let config = learned.config().unwrap();
        assert_eq!(config.label(), "linear+sh:4");
        assert_eq!(learned.calibration(), Calibration::None);
        // A basis given to a design that has none is refused, as `ModelConfig::check` says.
        let wrong = Asked {
            basis: Some(BasisChoice::Sh { band: 2 }),
            ..dsep
        };
        assert!(wrong.config().is_err());
    }
}
