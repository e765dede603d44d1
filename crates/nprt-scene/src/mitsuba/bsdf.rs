//! `<bsdf>`: every scattering model of the subset, nested ones (twosided, mask, bumpmap,
//! blendbsdf), indices of refraction by name or value, and microfacet roughness.

use anyhow::Result;
use glam::Vec3;
use roxmltree::Node;

use crate::bump_map::BumpMap;
use crate::conductor_ior::{conductor_names, named_conductor};
use crate::material::{Material, Scattering, Surface, MIN_ALPHA};
use crate::texture::Texture;

use super::{Ctx, Named};

/// Indices of refraction Mitsuba accepts by name (its documented table).
const NAMED_IORS: [(&str, f32); 23] = [
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

impl<'a> Ctx<'a> {
    /// An index of refraction given as a number or by material name.
    pub(super) fn ior_prop(&self, node: Node<'a, 'a>, name: &str, default: f32) -> Result<f32> {
        let Some(p) = self.prop(node, name) else {
            return Ok(default);
        };
        if p.has_tag_name("string") {
            let v = self.req(p, "value")?.to_lowercase();
            return match NAMED_IORS.iter().find(|(n, _)| *n == v) {
                Some((_, ior)) => Ok(*ior),
                None => self.fail(
                    p,
                    format!("unknown material '{v}' for an index of refraction; give a number"),
                ),
            };
        }
        let ior = self.float_value(p)?;
        if ior <= 0.0 {
            return self.fail(p, "an index of refraction must be positive");
        }
        Ok(ior)
    }

    /// The relative index int_ior / ext_ior of a dielectric interface.
    pub(super) fn relative_ior(&self, node: Node<'a, 'a>, int_default: f32) -> Result<f32> {
        let eta = self.ior_prop(node, "int_ior", int_default)?
            / self.ior_prop(node, "ext_ior", 1.000277)?;
        if eta == 1.0 {
            return self.fail(
                node,
                "int_ior and ext_ior are equal: the interface would be invisible",
            );
        }
        Ok(eta)
    }

    /// Parses a BSDF element into a new scene material; returns its index.
    pub(super) fn bsdf(&mut self, node: Node<'a, 'a>) -> Result<usize> {
        let material = self.bsdf_material(node)?;
        self.scene.materials.push(material);
        let index = self.scene.materials.len() - 1;
        if let Some(id) = self.attr(node, "id")? {
            self.named.insert(id, Named::Material(index));
        }
        Ok(index)
    }

    /// A BSDF nested in another; one declared with an id is also registered for `<ref>`.
    pub(super) fn nested_material(&mut self, node: Node<'a, 'a>) -> Result<Material> {
        let material = self.bsdf_material(node)?;
        if let Some(id) = self.attr(node, "id")? {
            self.scene.materials.push(material.clone());
            self.named
                .insert(id, Named::Material(self.scene.materials.len() - 1));
        }
        Ok(material)
    }

    /// The BSDFs a wrapper (twosided, mask, blendbsdf) holds, nested or referenced.
    pub(super) fn nested_materials(&mut self, node: Node<'a, 'a>) -> Result<Vec<Material>> {
        let mut out = vec![];
        for c in node.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "bsdf" => out.push(self.nested_material(c)?),
                "ref" => match self.named.get(&self.req(c, "id")?) {
                    Some(Named::Material(m)) => out.push(self.scene.materials[*m].clone()),
                    // A bump map's height, given by reference.
                    Some(Named::Texture(_)) if node.attribute("type") == Some("bumpmap") => {}
                    _ => return self.fail(c, "does not refer to a BSDF declared earlier"),
                },
                _ => {}
            }
        }
        Ok(out)
    }

    /// The one BSDF a wrapper holds.
    pub(super) fn single_nested(&mut self, node: Node<'a, 'a>) -> Result<Material> {
        let mut inner = self.nested_materials(node)?;
        if inner.len() != 1 {
            return self.fail(
                node,
                format!("needs exactly one nested BSDF, has {}", inner.len()),
            );
        }
        Ok(inner.remove(0))
    }

    pub(super) fn bsdf_material(&mut self, node: Node<'a, 'a>) -> Result<Material> {
        let name = node.attribute("id").unwrap_or("bsdf").to_string();
        let ty = node.attribute("type").unwrap_or("");
        let (kd, ks, alpha) = match ty {
            "twosided" => {
                let mut m = self.single_nested(node)?;
                if matches!(m.scattering, Scattering::Dielectric { .. }) {
                    return self.fail(node, "glass has no front and back: do not wrap it in twosided");
                }
                m.two_sided = true;
                if let Some(bump) = &mut m.bump {
                    bump.mirrored_behind = true;
                }
                m.name = name;
                return Ok(m);
            }
            "mask" => {
                let opacity = self.texture_prop(node, "opacity", Vec3::splat(0.5))?;
                let mut m = self.single_nested(node)?;
                if m.opacity.is_some() {
                    return self.fail(node, "a mask inside a mask is not supported");
                }
                m.opacity = Some(opacity);
                m.name = name;
                return Ok(m);
            }
            "diffuse" => {
                // Mitsuba 0.x also accepted diffuseReflectance here.
                let key = if self.legacy && self.prop(node, "reflectance").is_none() { "diffuse_reflectance" } else { "reflectance" };
                (self.texture_prop(node, key, Vec3::splat(0.5))?, Texture::constant(0.0), Texture::constant(1.0))
            }
            "conductor" | "roughconductor" => return self.conductor(node, &name, ty),
            "dielectric" | "thindielectric" => {
                let eta = self.relative_ior(node, 1.5046)?;
                let mut m = Material::new(
                    &name,
                    Surface::Direct {
                        kd: Texture::constant(0.0),
                        ks: self.texture_prop(node, "specular_reflectance", Vec3::ONE)?,
                        alpha: Texture::constant(MIN_ALPHA),
                    },
                    false,
                );
                m.transmittance = self.texture_prop(node, "specular_transmittance", Vec3::ONE)?;
                m.scattering = Scattering::Dielectric { eta, thin: ty == "thindielectric" };
                return Ok(m);
            }
            "plastic" | "roughplastic" => return self.plastic(node, &name, ty),
            "blendbsdf" => return self.blend(node, name),
            "bumpmap" => return self.bump_map(node, name),
            other => return self.fail(node, format!("unsupported BSDF plugin '{other}' (supported: diffuse, conductor, roughconductor, plastic, roughplastic, dielectric, thindielectric, twosided, mask, bumpmap, blendbsdf of diffuse + conductor)")),
        };
        Ok(Material::new(
            &name,
            Surface::Direct { kd, ks, alpha },
            false,
        ))
    }

    /// Mitsuba 3's `conductor` and `roughconductor` (`ty`): Fresnel-free, or with eta and k
    /// given or named by `material`.
    fn conductor(&mut self, node: Node<'a, 'a>, name: &str, ty: &str) -> Result<Material> {
        let alpha = if ty == "conductor" {
            MIN_ALPHA
        } else {
            self.microfacet_alpha(node, 0.1)?
        };
        let ks = self.texture_prop(node, "specular_reflectance", Vec3::ONE)?;
        let material = self.string_prop(node, "material")?;
        let scattering = match (
            self.prop(node, "eta").is_some() || self.prop(node, "k").is_some(),
            material.as_deref(),
        ) {
            (false, None | Some("none")) => Scattering::FresnelFree,
            (true, None) => Scattering::Conductor {
                eta: self.colour_prop(node, "eta", Vec3::ZERO)?,
                k: self.colour_prop(node, "k", Vec3::ONE)?,
            },
            (true, Some(_)) => {
                return self.fail(node, "give either a material or eta and k, not both")
            }
            (false, Some(named)) => match named_conductor(named) {
                Some((eta, k)) => Scattering::Conductor { eta, k },
                None => {
                    return self.fail(
                        node,
                        format!(
                            "unknown conductor material '{named}' (Mitsuba 3 names: {})",
                            conductor_names().collect::<Vec<_>>().join(", ")
                        ),
                    )
                }
            },
        };
        let mut m = Material::new(
            name,
            Surface::Direct {
                kd: Texture::constant(0.0),
                ks,
                alpha: Texture::constant(alpha),
            },
            false,
        );
        m.scattering = scattering;
        Ok(m)
    }

    /// Mitsuba 3's `plastic` and `roughplastic` (`ty`): a diffuse base under a dielectric coat.
    fn plastic(&mut self, node: Node<'a, 'a>, name: &str, ty: &str) -> Result<Material> {
        let rough = ty == "roughplastic";
        let alpha = if rough {
            self.microfacet_alpha(node, 0.1)?
        } else {
            MIN_ALPHA
        };
        let kd = self.texture_prop(node, "diffuse_reflectance", Vec3::splat(0.5))?;
        let ks = self.texture_prop(node, "specular_reflectance", Vec3::ONE)?;
        let (d_mean, s_mean) = (kd.mean(), ks.mean());
        let mut m = Material::new(
            name,
            Surface::Direct {
                kd,
                ks,
                alpha: Texture::constant(alpha),
            },
            false,
        );
        m.scattering = Scattering::Plastic {
            eta: self.relative_ior(node, 1.49)?,
            rough,
            nonlinear: self.bool_prop(node, "nonlinear", false)?,
            sampling_weight: if d_mean + s_mean > 0.0 {
                s_mean / (d_mean + s_mean)
            } else {
                0.5
            },
        };
        Ok(m)
    }

    /// Mitsuba 3's `bumpmap`: one nested texture (the height, whatever its name) and one BSDF.
    pub(super) fn bump_map(&mut self, node: Node<'a, 'a>, name: String) -> Result<Material> {
        let mut heights = vec![];
        for c in node.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "texture" => heights.push(self.texture(c)?),
                "ref" => {
                    if let Some(Named::Texture(t)) = self.named.get(&self.req(c, "id")?) {
                        heights.push(t.clone());
                    }
                }
                _ => {}
            }
        }
        if heights.len() != 1 {
            return self.fail(
                node,
                format!(
                    "needs exactly one nested texture (the height), has {}",
                    heights.len()
                ),
            );
        }
        let height = heights.remove(0);
        let scale = self.float_prop(node, "scale", 1.0)?;
        let mut m = self.single_nested(node)?;
        if m.bump.is_some() {
            return self.fail(node, "a bump map inside a bump map is not supported");
        }
        if m.opacity.is_some() {
            // Mitsuba would shadow the pass-through light too; nprt's mask passes light unbumped.
            return self.fail(
                node,
                "a mask inside a bump map is not supported: put the mask outside it",
            );
        }
        m.bump = Some(BumpMap {
            height,
            scale,
            mirrored_behind: false,
        });
        m.name = name;
        Ok(m)
    }

    /// `blendbsdf` of one diffuse and one (rough)conductor is exactly DESIGN.md's model:
    /// kd = (1−w)·ρ, ks = w·ks with weight w on the second BSDF.
    pub(super) fn blend(&mut self, node: Node<'a, 'a>, name: String) -> Result<Material> {
        let w = match self.texture_prop(node, "weight", Vec3::splat(0.5))? {
            Texture::Constant(c) => c.x,
            _ => return self.fail(node, "a textured blend weight is not supported"),
        };
        if !(0.0..=1.0).contains(&w) {
            self.scene.warnings.push(format!(
                "{}: blend weight {w} is outside [0, 1]; held to it",
                self.at(node)
            ));
        }
        let w = w.clamp(0.0, 1.0);
        let parts = self.nested_materials(node)?;
        if parts.len() != 2 {
            return self.fail(node, "blendbsdf needs exactly two nested BSDFs");
        }
        let consts = |m: &Material| match &m.surface {
            _ if m.scattering != Scattering::FresnelFree || m.opacity.is_some() => None,
            Surface::Direct {
                kd: Texture::Constant(kd),
                ks: Texture::Constant(ks),
                alpha: Texture::Constant(a),
            } => Some((*kd, *ks, a.x)),
            _ => None,
        };
        match (consts(&parts[0]), consts(&parts[1])) {
            (Some((kd, ks0, _)), Some((kd1, ks, a))) if ks0 == Vec3::ZERO && kd1 == Vec3::ZERO => {
                Ok(Material { two_sided: false, ..Material::glossy(&name, kd * (1.0 - w), ks * w, a) })
            }
            _ => self.fail(node, "blendbsdf is supported only as (diffuse, conductor/roughconductor) with constant parameters"),
        }
    }

    pub(super) fn microfacet_alpha(&mut self, node: Node<'a, 'a>, default: f32) -> Result<f32> {
        let dist = self
            .string_prop(node, "distribution")?
            .unwrap_or_else(|| "beckmann".into());
        if dist != "ggx" {
            self.scene.warnings.push(format!(
                "{}: distribution '{dist}' is traced as GGX",
                self.at(node)
            ));
        }
        if self.prop(node, "alpha_u").is_some() || self.prop(node, "alpha_v").is_some() {
            let (u, v) = (
                self.float_prop(node, "alpha_u", default)?,
                self.float_prop(node, "alpha_v", default)?,
            );
            if (u - v).abs() > 1e-6 {
                return self.fail(
                    node,
                    "anisotropic roughness (alpha_u != alpha_v) is not supported",
                );
            }
            return Ok(u.max(MIN_ALPHA));
        }
        match self.prop(node, "alpha") {
            Some(p) if p.has_tag_name("float") => Ok(self.float_value(p)?.max(MIN_ALPHA)),
            Some(p) => self.fail(p, "alpha must be a <float>"),
            None => Ok(default),
        }
    }
}
