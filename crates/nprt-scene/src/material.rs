//! Materials in DESIGN.md's model: f = kd/π + ks·D(α)·G(α) / (4 |ωi·n| |ωo·n|), GGX with Smith
//! shadowing, no Fresnel term (Mitsuba's `diffuse` plus `roughconductor` with
//! `material="none"`). Formats with other parametrisations map onto it here.

use glam::{Vec2, Vec3};

use crate::texture::Texture;

/// Smallest GGX alpha we trace; smooth conductors and plastics become near-mirrors of this
/// roughness (the model has no delta lobe).
pub const MIN_ALPHA: f32 = 1e-3;

/// The BSDF parameters at one surface point: what the G-buffer stores.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfParams {
    pub kd: Vec3,
    pub ks: Vec3,
    /// GGX alpha (not perceptual roughness).
    pub alpha: f32,
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
    /// ones shade both sides alike (Mitsuba's `twosided`, glTF's `doubleSided`).
    pub two_sided: bool,
}

impl Material {
    pub fn diffuse(name: &str, kd: Vec3) -> Self {
        Self::glossy(name, kd, Vec3::ZERO, 1.0)
    }

    pub fn glossy(name: &str, kd: Vec3, ks: Vec3, alpha: f32) -> Self {
        Material {
            name: name.to_string(),
            surface: Surface::Direct {
                kd: Texture::Constant(kd),
                ks: Texture::Constant(ks),
                alpha: Texture::constant(alpha),
            },
            two_sided: true,
        }
    }

    /// True when no parameter varies over the surface.
    pub fn surface_is_constant(&self) -> bool {
        match &self.surface {
            Surface::Direct { kd, ks, alpha } => {
                kd.is_constant() && ks.is_constant() && alpha.is_constant()
            }
            Surface::MetallicRoughness {
                base,
                metallic_roughness,
            } => base.is_constant() && metallic_roughness.is_constant(),
        }
    }

    pub fn eval(&self, uv: Vec2) -> BsdfParams {
        match &self.surface {
            Surface::Direct { kd, ks, alpha } => BsdfParams {
                kd: kd.eval(uv),
                ks: ks.eval(uv),
                alpha: alpha.eval(uv).x.max(MIN_ALPHA),
            },
            Surface::MetallicRoughness {
                base,
                metallic_roughness,
            } => {
                let b = base.eval(uv);
                let mr = metallic_roughness.eval(uv);
                let (rough, metal) = (mr.y.clamp(0.0, 1.0), mr.z.clamp(0.0, 1.0));
                BsdfParams {
                    kd: b * (1.0 - metal),
                    ks: Vec3::splat(0.04).lerp(b, metal),
                    alpha: (rough * rough).max(MIN_ALPHA),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gltf_metallic_roughness_mapping() {
        let m = Material {
            name: "m".into(),
            surface: Surface::MetallicRoughness {
                base: Texture::Constant(Vec3::new(0.8, 0.4, 0.2)),
                metallic_roughness: Texture::Constant(Vec3::new(0.0, 0.5, 0.25)),
            },
            two_sided: false,
        };
        let p = m.eval(Vec2::ZERO);
        assert!((p.kd - Vec3::new(0.6, 0.3, 0.15)).length() < 1e-6);
        assert!((p.ks - Vec3::new(0.23, 0.13, 0.08)).length() < 1e-6);
        assert!((p.alpha - 0.25).abs() < 1e-6);
    }
}
