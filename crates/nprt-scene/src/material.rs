//! Materials in DESIGN.md's model: f = kd/π + ks·D(α)·G(α) / (4 |ωi·n| |ωo·n|), GGX with Smith
//! shadowing, no Fresnel term (Mitsuba's `diffuse` plus `roughconductor` with
//! `material="none"`), and what real scenes need beyond it: conductors with a complex index
//! (the specular lobe times their Fresnel reflectance), plastics, smooth glass, and opacity
//! masks.
//! Formats with other parametrisations map onto it here. The G-buffer records every surface in
//! the model's terms ([`BsdfParams::gbuffer`]).

use glam::{Vec2, Vec3};

use crate::bump_map::BumpMap;
use crate::color::luminance;
use crate::fresnel::{fresnel_conductor, fresnel_dielectric};
use crate::texture::Texture;

/// Smallest GGX alpha we trace; smooth conductors and plastics become near-mirrors of this
/// roughness (the model has no delta lobe).
pub const MIN_ALPHA: f32 = 1e-3;

/// How a surface scatters light beyond its (kd, ks, α) description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Scattering {
    /// DESIGN.md's Fresnel-free model.
    FresnelFree,
    /// Mitsuba's (rough)conductor of complex index η + ik: the specular lobe is ks times the
    /// conductor's Fresnel reflectance at the microfacet.
    Conductor { eta: Vec3, k: Vec3 },
    /// Smooth glass of relative index `eta` (Mitsuba's `dielectric`): specular reflection with
    /// weight ks and refraction with weight kt, chosen by Fresnel. `thin` is Mitsuba's
    /// `thindielectric`: a slab whose inter-reflections are summed and whose transmission does
    /// not bend.
    Dielectric { eta: f32, thin: bool },
    /// Mitsuba's `plastic` (`rough` = false: a smooth coat, delta reflection) and
    /// `roughplastic`: a dielectric coat of relative index `eta` with a GGX lobe ks·F·D·G over
    /// a diffuse base kd, seen through the coat's transmittance and inter-reflections
    /// (`nonlinear`: the base's colour shifts with them). `sampling_weight` is Mitsuba's
    /// share of specular samples, mean(ks) / (mean(kd) + mean(ks)) over the textures.
    Plastic {
        eta: f32,
        rough: bool,
        nonlinear: bool,
        sampling_weight: f32,
    },
}

/// The BSDF parameters at one surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfParams {
    pub kd: Vec3,
    /// Specular reflectance: the lobe's scale before any Fresnel term.
    pub ks: Vec3,
    /// GGX alpha (not perceptual roughness).
    pub alpha: f32,
    /// Specular transmittance of glass (zero elsewhere).
    pub kt: Vec3,
    /// Fraction of light that meets the surface at all (Mitsuba's `mask`); the rest passes
    /// straight through.
    pub opacity: f32,
    pub scattering: Scattering,
}

impl BsdfParams {
    pub fn new(kd: Vec3, ks: Vec3, alpha: f32) -> Self {
        BsdfParams {
            kd,
            ks,
            alpha,
            kt: Vec3::ZERO,
            opacity: 1.0,
            scattering: Scattering::FresnelFree,
        }
    }

    /// Specular reflectance at normal incidence, the Fresnel term included.
    pub fn normal_incidence_ks(&self) -> Vec3 {
        match self.scattering {
            Scattering::FresnelFree => self.ks,
            Scattering::Conductor { eta, k } => self.ks * fresnel_conductor(1.0, eta, k),
            Scattering::Dielectric { eta, .. } | Scattering::Plastic { eta, .. } => {
                self.ks * fresnel_dielectric(1.0, eta).r
            }
        }
    }

    /// What the G-buffer stores, (kd, ks, α) of DESIGN.md's model: ks at normal incidence, and
    /// a masked surface's parameters scaled by its opacity (what it reflects on average). Glass
    /// has kd = 0 and α at its floor: the G-buffer sees its reflecting surface only.
    /// Each is held to [0, 1], the range a dataset's reader accepts: a scene may state
    /// reflectances above 1 or α of many (Mitsuba traces them as given, as does nprt), but the
    /// network's inputs stay where a damaged file can be told apart (docs/limits.md).
    pub fn gbuffer(&self) -> (Vec3, Vec3, f32) {
        (
            (self.kd * self.opacity).clamp(Vec3::ZERO, Vec3::ONE),
            (self.normal_incidence_ks() * self.opacity).clamp(Vec3::ZERO, Vec3::ONE),
            self.alpha.min(1.0),
        )
    }
}

/// How a material's textures define (kd, ks, α).
#[derive(Clone, Debug)]
pub enum Surface {
    /// kd, ks and α given directly (α in the texture's `.x`).
    Direct {
        kd: Texture,
        ks: Texture,
        alpha: Texture,
    },
    /// glTF metallic-roughness: kd = base·(1−m), ks = mix(0.04, base, m), α = roughness².
    /// `metallic_roughness` holds roughness in `.y` and metallic in `.z` (glTF's G and B).
    MetallicRoughness {
        base: Texture,
        metallic_roughness: Texture,
    },
}

#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    pub surface: Surface,
    /// One-sided surfaces reflect nothing seen from the back (Mitsuba's default); two-sided
    /// ones shade both sides alike (Mitsuba's `twosided`, glTF's `doubleSided`). Glass is
    /// neither: its two sides are inside and outside.
    pub two_sided: bool,
    pub scattering: Scattering,
    /// Specular transmittance (glass only).
    pub transmittance: Texture,
    /// Opacity, the luminance of this texture (Mitsuba's `mask`); `None` is opaque.
    pub opacity: Option<Texture>,
    /// A height field tilting the shading normal (Mitsuba's `bumpmap`).
    pub bump: Option<BumpMap>,
}

impl Material {
    /// Holds the reflectances (kd, ks, or glTF's base colour) and the transmittance to [0, 1],
    /// as light that is not created or taken away needs; a warning for each it changed.
    pub fn clamp_reflectances(&mut self) -> Vec<String> {
        let mut changed = Vec::new();
        let mut clamp = |what: &str, t: &mut Texture| {
            if let Some(c) = t.clamped_to_unit() {
                *t = c;
                changed.push(what.to_string());
            }
        };
        match &mut self.surface {
            Surface::Direct { kd, ks, .. } => {
                clamp("diffuse reflectance", kd);
                clamp("specular reflectance", ks);
            }
            Surface::MetallicRoughness { base, .. } => clamp("base colour", base),
        }
        clamp("transmittance", &mut self.transmittance);
        (changed.into_iter())
            .map(|what| {
                format!(
                    "material '{}': its {what} goes outside [0, 1] (light would be created or \
                     negative); held to [0, 1]",
                    self.name
                )
            })
            .collect()
    }

    /// An opaque material of DESIGN.md's model.
    pub fn new(name: &str, surface: Surface, two_sided: bool) -> Self {
        Material {
            name: name.to_string(),
            surface,
            two_sided,
            scattering: Scattering::FresnelFree,
            transmittance: Texture::constant(0.0),
            opacity: None,
            bump: None,
        }
    }

    pub fn diffuse(name: &str, kd: Vec3) -> Self {
        Self::glossy(name, kd, Vec3::ZERO, 1.0)
    }

    pub fn glossy(name: &str, kd: Vec3, ks: Vec3, alpha: f32) -> Self {
        Self::new(
            name,
            Surface::Direct {
                kd: Texture::Constant(kd),
                ks: Texture::Constant(ks),
                alpha: Texture::constant(alpha),
            },
            true,
        )
    }

    /// True when no parameter varies over the surface.
    pub fn surface_is_constant(&self) -> bool {
        let surface = match &self.surface {
            Surface::Direct { kd, ks, alpha } => {
                kd.is_constant() && ks.is_constant() && alpha.is_constant()
            }
            Surface::MetallicRoughness {
                base,
                metallic_roughness,
            } => base.is_constant() && metallic_roughness.is_constant(),
        };
        surface
            && self.transmittance.is_constant()
            && self.opacity.as_ref().is_none_or(Texture::is_constant)
            && self.bump.is_none()
    }

    pub fn eval(&self, uv: Vec2) -> BsdfParams {
        let mut p = match &self.surface {
            Surface::Direct { kd, ks, alpha } => {
                BsdfParams::new(kd.eval(uv), ks.eval(uv), alpha.eval(uv).x.max(MIN_ALPHA))
            }
            Surface::MetallicRoughness {
                base,
                metallic_roughness,
            } => {
                let b = base.eval(uv);
                let mr = metallic_roughness.eval(uv);
                let (rough, metal) = (mr.y.clamp(0.0, 1.0), mr.z.clamp(0.0, 1.0));
                BsdfParams::new(
                    b * (1.0 - metal),
                    Vec3::splat(0.04).lerp(b, metal),
                    (rough * rough).max(MIN_ALPHA),
                )
            }
        };
        p.scattering = self.scattering;
        p.kt = self.transmittance.eval(uv);
        if let Some(o) = &self.opacity {
            p.opacity = luminance(o.eval(uv)).clamp(0.0, 1.0);
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gltf_metallic_roughness_mapping() {
        let m = Material::new(
            "m",
            Surface::MetallicRoughness {
                base: Texture::Constant(Vec3::new(0.8, 0.4, 0.2)),
                metallic_roughness: Texture::Constant(Vec3::new(0.0, 0.5, 0.25)),
            },
            false,
        );
        let p = m.eval(Vec2::ZERO);
        assert!((p.kd - Vec3::new(0.6, 0.3, 0.15)).length() < 1e-6);
        assert!((p.ks - Vec3::new(0.23, 0.13, 0.08)).length() < 1e-6);
        assert!((p.alpha - 0.25).abs() < 1e-6);
    }
}
