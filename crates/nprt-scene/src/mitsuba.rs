//! Mitsuba XML scenes, the subset DESIGN.md lists: obj/ply/rectangle/cube/sphere shapes;
//! diffuse/conductor/roughconductor (RGB or named index)/plastic/roughplastic/dielectric/
//! thindielectric/twosided/mask/bumpmap (and diffuse+conductor `blendbsdf`) BSDFs;
//! bitmap/checkerboard textures; envmap/constant emitters; a perspective sensor with hdrfilm and
//! sampler; the path integrator; `<default>`, `$name` and `<ref>`. Files of format version 0.x
//! (Mitsuba 0.5/0.6, e.g. Bitterli's scenes) are upgraded as Mitsuba 3 upgrades them: camelCase
//! property names, a diffuse BSDF's `diffuseReflectance`, texture `uscale`/`uoffset`. Shapes
//! carrying an area emitter are removed with a warning (the scene is lit by its environment only).
//! Anything else stops with an error naming the file, line and element.

use std::borrow::Cow;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context, Result};
use glam::{Affine2, Mat3, Mat4, Vec2, Vec3};
use roxmltree::{Document, Node};

use crate::bump_map::BumpMap;
use crate::camera::{look_at, Camera, FovAxis};
use crate::conductor_ior::{conductor_names, named_conductor};
use crate::envmap::EnvMap;
use crate::material::{Material, Scattering, Surface, MIN_ALPHA};
use crate::mesh::Mesh;
use crate::mesh_io::load_mesh;
use crate::scene::{Scene, SceneOptions};
use crate::texture::{Bitmap, Texture};

/// Tessellation of Mitsuba's analytic `sphere` (segments around the pole axis = 2×).
const SPHERE_SEGMENTS: u32 = 96;

pub fn load(path: &Path, opts: &SceneOptions) -> Result<Scene> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read scene file '{}'", path.display()))?;
    parse(&text, path, opts)
}

/// Parses the Mitsuba scene `text` of the file `path` (which names it in errors and anchors
/// its relative file references).
pub fn parse(text: &str, path: &Path, opts: &SceneOptions) -> Result<Scene> {
    let file = path.display().to_string();
    let doc =
        Document::parse(text).map_err(|e| anyhow!("scene file '{file}' is not valid XML: {e}"))?;
    let root = doc.root_element();
    if root.tag_name().name() != "scene" {
        bail!(
            "scene file '{file}': the root element is <{}>, expected <scene>",
            root.tag_name().name()
        );
    }
    let version = root.attribute("version").unwrap_or("3.0.0");
    let major: u32 = version
        .split('.')
        .next()
        .and_then(|m| m.trim().parse().ok())
        .ok_or_else(|| {
            anyhow!("scene file '{file}': version '{version}' is not a version number")
        })?;
    let mut params: HashMap<String, String> = HashMap::new();
    for d in root.children().filter(|n| n.has_tag_name("default")) {
        let (Some(name), Some(value)) = (d.attribute("name"), d.attribute("value")) else {
            bail!("{}: <default> needs name and value", pos(&file, &doc, d));
        };
        params.insert(name.to_string(), value.to_string());
    }
    for (name, value) in &opts.set {
        if !params.contains_key(name) && !text.contains(&format!("${name}")) {
            bail!("scene file '{file}' has no parameter '{name}' to set (no <default name=\"{name}\"> and no ${name})");
        }
        params.insert(name.clone(), value.clone());
    }
    let mut ctx = Ctx {
        file: file.clone(),
        doc: &doc,
        base: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        params,
        named: HashMap::new(),
        bitmaps: HashMap::new(),
        scene: Scene::empty(&file),
        rfilter_box: false,
        legacy: major < 2,
    };
    for node in root.children().filter(Node::is_element) {
        ctx.top_level(node)?;
    }
    if ctx.scene.camera.is_some() && !ctx.rfilter_box {
        ctx.scene.warnings.push(format!("{file}: the film's reconstruction filter is not 'box'; nprt reference renders with a box filter"));
    }
    Ok(ctx.scene)
}

fn pos(file: &str, doc: &Document, node: Node) -> String {
    let p = doc.text_pos_at(node.range().start);
    let ty = node
        .attribute("type")
        .map(|t| format!(" type=\"{t}\""))
        .unwrap_or_default();
    format!(
        "{file}:{}:{}: <{}{ty}>",
        p.row,
        p.col,
        node.tag_name().name()
    )
}

struct Ctx<'a> {
    file: String,
    doc: &'a Document<'a>,
    base: PathBuf,
    params: HashMap<String, String>,
    /// Objects declared with an `id`: materials (by index) and textures.
    named: HashMap<String, Named>,
    bitmaps: HashMap<(PathBuf, bool), Arc<Bitmap>>,
    scene: Scene,
    rfilter_box: bool,
    /// Format version 0.x: property names are camelCase.
    legacy: bool,
}

/// Mitsuba 3's upgrade of a 0.x property name: `toWorld` → `to_world`, `intIOR` → `int_ior`
/// (an upper-case letter after a lower-case one starts a word, and the capitals that follow
/// belong to it).
fn snake_case(name: &str) -> Cow<'_, str> {
    let b = name.as_bytes();
    if !b
        .windows(2)
        .any(|w| w[0].is_ascii_lowercase() && w[1].is_ascii_uppercase())
    {
        return Cow::Borrowed(name);
    }
    let mut out = String::with_capacity(name.len() + 4);
    let mut i = 0;
    while i < b.len() {
        if i > 0 && b[i - 1].is_ascii_lowercase() && b[i].is_ascii_uppercase() {
            out.push('_');
            while i < b.len() && b[i].is_ascii_uppercase() {
                out.push(b[i].to_ascii_lowercase() as char);
                i += 1;
            }
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    Cow::Owned(out)
}

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

#[derive(Clone)]
enum Named {
    Material(usize),
    Texture(Texture),
}

impl<'a> Ctx<'a> {
    fn at(&self, node: Node) -> String {
        pos(&self.file, self.doc, node)
    }

    fn fail<T>(&self, node: Node, msg: impl std::fmt::Display) -> Result<T> {
        bail!("{}: {msg}", self.at(node))
    }

    /// An attribute with `$name` parameters substituted.
    fn attr(&self, node: Node, key: &str) -> Result<Option<String>> {
        let Some(raw) = node.attribute(key) else {
            return Ok(None);
        };
        let mut out = String::new();
        let mut rest = raw;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let tail = &rest[i + 1..];
            let end = tail
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(tail.len());
            let name = &tail[..end];
            match self.params.get(name) {
                Some(v) => out.push_str(v),
                None => {
                    return self.fail(
                        node,
                        format!(
                            "parameter ${name} has no <default> and was not set (--set {name}=...)"
                        ),
                    )
                }
            }
            rest = &tail[end..];
        }
        out.push_str(rest);
        Ok(Some(out))
    }

    fn req(&self, node: Node, key: &str) -> Result<String> {
        match self.attr(node, key)? {
            Some(v) => Ok(v),
            None => self.fail(node, format!("missing attribute '{key}'")),
        }
    }

    fn numbers(&self, node: Node, s: &str) -> Result<Vec<f32>> {
        s.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .map(|t| {
                match t.parse::<f32>() {
                    Ok(x) if x.is_finite() => Ok(x),
                    // 1e40 parses as infinity in f32: as unusable as "inf" or "nan".
                    Ok(_) => self.fail(node, format!("'{t}' is not a finite number")),
                    Err(_) => self.fail(node, format!("'{t}' is not a number")),
                }
            })
            .collect()
    }

    fn float_value(&self, node: Node) -> Result<f32> {
        let v = self.req(node, "value")?;
        match self.numbers(node, &v)?.as_slice() {
            [x] => Ok(*x),
            _ => self.fail(node, format!("expected one number, got '{v}'")),
        }
    }

    /// A vector given as `value="x, y, z"` or as x/y/z attributes (missing ones = `default`).
    fn vec3_value(&self, node: Node, default: f32) -> Result<Vec3> {
        if let Some(v) = self.attr(node, "value")? {
            return match self.numbers(node, &v)?.as_slice() {
                [s] => Ok(Vec3::splat(*s)),
                [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
                _ => self.fail(node, format!("expected 1 or 3 numbers, got '{v}'")),
            };
        }
        let mut out = Vec3::splat(default);
        for (k, key) in ["x", "y", "z"].iter().enumerate() {
            if let Some(v) = self.attr(node, key)? {
                out[k] = self.numbers(node, &v)?.first().copied().unwrap_or(default);
            }
        }
        Ok(out)
    }

    fn path(&self, node: Node, value: &str) -> Result<PathBuf> {
        let p = self.base.join(value);
        if !p.exists() {
            return self.fail(node, format!("file '{}' does not exist", p.display()));
        }
        Ok(p)
    }

    /// The child property element with `name="..."` (in Mitsuba 3's spelling).
    fn prop(&self, node: Node<'a, 'a>, name: &str) -> Option<Node<'a, 'a>> {
        node.children().find(|c| {
            c.is_element()
                && c.attribute("name").is_some_and(|n| {
                    if self.legacy {
                        snake_case(n) == name
                    } else {
                        n == name
                    }
                })
        })
    }

    /// An index of refraction given as a number or by material name.
    fn ior_prop(&self, node: Node<'a, 'a>, name: &str, default: f32) -> Result<f32> {
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
    fn relative_ior(&self, node: Node<'a, 'a>, int_default: f32) -> Result<f32> {
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

    /// A property that must be one colour (not a texture).
    fn colour_prop(&mut self, node: Node<'a, 'a>, name: &str, default: Vec3) -> Result<Vec3> {
        match self.texture_prop(node, name, default)? {
            Texture::Constant(c) => Ok(c),
            _ => self.fail(node, format!("'{name}' must be a colour, not a texture")),
        }
    }

    fn float_prop(&self, node: Node<'a, 'a>, name: &str, default: f32) -> Result<f32> {
        self.prop(node, name)
            .map_or(Ok(default), |p| self.float_value(p))
    }

    fn int_prop(&self, node: Node<'a, 'a>, name: &str) -> Result<Option<i64>> {
        let Some(p) = self.prop(node, name) else {
            return Ok(None);
        };
        let v = self.req(p, "value")?;
        v.trim()
            .parse::<i64>()
            .map(Some)
            .or_else(|_| self.fail(p, format!("'{v}' is not an integer")))
    }

    fn string_prop(&self, node: Node<'a, 'a>, name: &str) -> Result<Option<String>> {
        self.prop(node, name)
            .map_or(Ok(None), |p| self.req(p, "value").map(Some))
    }

    fn bool_prop(&self, node: Node<'a, 'a>, name: &str, default: bool) -> Result<bool> {
        let Some(p) = self.prop(node, name) else {
            return Ok(default);
        };
        match self.req(p, "value")?.as_str() {
            "true" | "1" => Ok(true),
            "false" | "0" => Ok(false),
            v => self.fail(p, format!("'{v}' is not a boolean")),
        }
    }

    /// A colour or texture property; `default` when absent.
    fn texture_prop(&mut self, node: Node<'a, 'a>, name: &str, default: Vec3) -> Result<Texture> {
        let Some(p) = self.prop(node, name) else {
            return Ok(Texture::Constant(default));
        };
        match p.tag_name().name() {
            "rgb" => Ok(Texture::Constant(self.vec3_value(p, 0.0)?)),
            "float" => Ok(Texture::Constant(Vec3::splat(self.float_value(p)?))),
            "spectrum" => {
                let v = self.req(p, "value")?;
                if v.contains(':') {
                    return self.fail(p, "sampled spectra are not supported; give an <rgb> value");
                }
                Ok(Texture::Constant(self.vec3_value(p, 0.0)?))
            }
            "texture" => self.texture(p),
            "ref" => match self.named.get(&self.req(p, "id")?) {
                Some(Named::Texture(t)) => Ok(t.clone()),
                _ => self.fail(p, "does not refer to a texture declared earlier"),
            },
            other => self.fail(p, format!("<{other}> cannot give a colour")),
        }
    }

    fn texture(&mut self, node: Node<'a, 'a>) -> Result<Texture> {
        let to_uv = match self.prop(node, "to_uv") {
            Some(t) => {
                let m = self.transform(t)?;
                Affine2::from_cols(
                    m.x_axis.truncate().truncate(),
                    m.y_axis.truncate().truncate(),
                    m.w_axis.truncate().truncate(),
                )
            }
            None => Affine2::IDENTITY,
        };
        // Mitsuba 0.x placed bitmaps by uoffset/voffset/uscale/vscale.
        let to_uv = if self.legacy {
            let scale = Vec2::new(
                self.float_prop(node, "uscale", 1.0)?,
                self.float_prop(node, "vscale", 1.0)?,
            );
            let offset = Vec2::new(
                self.float_prop(node, "uoffset", 0.0)?,
                self.float_prop(node, "voffset", 0.0)?,
            );
            Affine2::from_scale(scale) * Affine2::from_translation(offset) * to_uv
        } else {
            to_uv
        };
        match node.attribute("type").unwrap_or("") {
            "bitmap" => {
                let filename = self
                    .string_prop(node, "filename")?
                    .ok_or_else(|| anyhow!("{}: missing 'filename'", self.at(node)))?;
                let path = self.path(node, &filename)?;
                let raw = self.bool_prop(node, "raw", false)?;
                if let Some(w) = self.string_prop(node, "wrap_mode")? {
                    if w != "repeat" {
                        self.scene.warnings.push(format!(
                            "{}: wrap_mode '{w}' is traced as 'repeat'",
                            self.at(node)
                        ));
                    }
                }
                let key = (path.clone(), raw);
                let image = match self.bitmaps.get(&key) {
                    Some(b) => b.clone(),
                    None => {
                        let b = Arc::new(Bitmap::load(&path, raw).with_context(|| self.at(node))?);
                        self.bitmaps.insert(key, b.clone());
                        b
                    }
                };
                Ok(Texture::Bitmap {
                    image,
                    to_uv,
                    factor: Vec3::ONE,
                })
            }
            "checkerboard" => {
                let c0 = self.texture_prop(node, "color0", Vec3::splat(0.4))?;
                let c1 = self.texture_prop(node, "color1", Vec3::splat(0.2))?;
                match (c0, c1) {
                    (Texture::Constant(color0), Texture::Constant(color1)) => {
                        Ok(Texture::Checkerboard {
                            color0,
                            color1,
                            to_uv,
                        })
                    }
                    _ => self.fail(node, "checkerboard colours must be constants"),
                }
            }
            other => self.fail(
                node,
                format!("unsupported texture plugin '{other}' (supported: bitmap, checkerboard)"),
            ),
        }
    }

    fn transform(&self, node: Node) -> Result<Mat4> {
        let mut m = Mat4::IDENTITY;
        for t in node.children().filter(Node::is_element) {
            let step = match t.tag_name().name() {
                "translate" => Mat4::from_translation(self.vec3_value(t, 0.0)?),
                "scale" => Mat4::from_scale(self.vec3_value(t, 1.0)?),
                "rotate" => {
                    let axis = self.vec3_value(t, 0.0)?;
                    let angle: f32 = self
                        .req(t, "angle")?
                        .trim()
                        .parse()
                        .or_else(|_| self.fail(t, "angle is not a number"))?;
                    if axis.length_squared() == 0.0 {
                        return self.fail(t, "rotation axis is zero");
                    }
                    Mat4::from_axis_angle(axis.normalize(), angle.to_radians())
                }
                "matrix" => {
                    let v = self.numbers(t, &self.req(t, "value")?)?;
                    match v.len() {
                        16 => Mat4::from_cols_array(&v.try_into().unwrap()).transpose(),
                        9 => Mat4::from_mat3(
                            Mat3::from_cols_array(&v.try_into().unwrap()).transpose(),
                        ),
                        n => {
                            return self.fail(t, format!("a matrix needs 9 or 16 values, got {n}"))
                        }
                    }
                }
                "lookat" | "lookAt" => {
                    let get = |k: &str| -> Result<Vec3> {
                        let v = self.numbers(t, &self.req(t, k)?)?;
                        if v.len() != 3 {
                            return self.fail(t, format!("'{k}' needs 3 numbers"));
                        }
                        Ok(Vec3::new(v[0], v[1], v[2]))
                    };
                    let up = if t.attribute("up").is_some() {
                        get("up")?
                    } else {
                        Vec3::Y
                    };
                    look_at(get("origin")?, get("target")?, up)
                }
                other => return self.fail(t, format!("unknown transform operation <{other}>")),
            };
            m = step * m;
        }
        Ok(m)
    }

    fn top_level(&mut self, node: Node<'a, 'a>) -> Result<()> {
        match node.tag_name().name() {
            "default" => Ok(()),
            "integrator" => self.integrator(node),
            "sensor" => self.sensor(node),
            "shape" => self.shape(node),
            "emitter" => self.emitter(node),
            "bsdf" => match self.attr(node, "id")? {
                Some(_) => self.bsdf(node).map(|_| ()),
                // Nothing can refer to it (Bitterli's scenes wrap bump maps this way), but BSDFs
                // declared inside it with ids can be.
                None => {
                    for inner in node.children().filter(|c| c.has_tag_name("bsdf")) {
                        self.nested_material(inner)?;
                    }
                    self.scene.warnings.push(format!(
                        "{}: a top-level BSDF without an id is never used (as in Mitsuba); only BSDFs declared inside it with an id are",
                        self.at(node)
                    ));
                    Ok(())
                }
            },
            "texture" => {
                let id = self.req(node, "id")?;
                let t = self.texture(node)?;
                self.named.insert(id, Named::Texture(t));
                Ok(())
            }
            other => self.fail(node, format!("unsupported element <{other}>")),
        }
    }

    fn integrator(&mut self, node: Node<'a, 'a>) -> Result<()> {
        if node.attribute("type") != Some("path") {
            return self.fail(node, "unsupported integrator (only 'path')");
        }
        let depth = self.int_prop(node, "max_depth")?.unwrap_or(-1);
        self.scene.max_depth = if depth < 0 { None } else { Some(depth as u32) };
        if let Some(rr) = self.int_prop(node, "rr_depth")? {
            self.scene.rr_depth = rr.max(1) as u32;
        }
        Ok(())
    }

    fn sensor(&mut self, node: Node<'a, 'a>) -> Result<()> {
        if node.attribute("type") != Some("perspective") {
            return self.fail(node, "unsupported sensor (only 'perspective')");
        }
        let to_world = match self.prop(node, "to_world") {
            Some(t) => self.transform(t)?,
            None => Mat4::IDENTITY,
        };
        let fov_axis = match self
            .string_prop(node, "fov_axis")?
            .as_deref()
            .unwrap_or("x")
        {
            "x" => FovAxis::X,
            "y" => FovAxis::Y,
            "diagonal" => FovAxis::Diagonal,
            "smaller" => FovAxis::Smaller,
            "larger" => FovAxis::Larger,
            other => return self.fail(node, format!("unknown fov_axis '{other}'")),
        };
        if self.prop(node, "focal_length").is_some() {
            return self.fail(node, "focal_length is not supported; give fov");
        }
        let fov_deg = self.float_prop(node, "fov", 0.0)?;
        if !(fov_deg > 0.0 && fov_deg < 180.0) {
            return self.fail(node, "needs a 'fov' between 0 and 180 degrees");
        }
        let (mut width, mut height) = (768, 576);
        for child in node.children().filter(Node::is_element) {
            match child.tag_name().name() {
                "film" => {
                    if child.attribute("type") != Some("hdrfilm") {
                        return self.fail(child, "unsupported film (only 'hdrfilm')");
                    }
                    width = self.int_prop(child, "width")?.unwrap_or(768).max(1) as u32;
                    height = self.int_prop(child, "height")?.unwrap_or(576).max(1) as u32;
                    if self.prop(child, "crop_width").is_some()
                        || self.prop(child, "crop_offset_x").is_some()
                    {
                        return self.fail(child, "film crop windows are not supported");
                    }
                    self.rfilter_box = child
                        .children()
                        .any(|r| r.has_tag_name("rfilter") && r.attribute("type") == Some("box"));
                }
                "sampler" => {
                    if let Some(n) = self.int_prop(child, "sample_count")? {
                        self.scene.spp = Some(n.max(1) as u32);
                    }
                }
                _ => {}
            }
        }
        self.scene.camera = Some(Camera {
            to_world,
            fov_deg,
            fov_axis,
            width,
            height,
        });
        Ok(())
    }

    fn emitter(&mut self, node: Node<'a, 'a>) -> Result<()> {
        if self.scene.envmap.is_some() {
            return self.fail(node, "only one environment emitter is supported");
        }
        let map = match node.attribute("type").unwrap_or("") {
            "envmap" => {
                let filename = self
                    .string_prop(node, "filename")?
                    .ok_or_else(|| anyhow!("{}: missing 'filename'", self.at(node)))?;
                let path = self.path(node, &filename)?;
                let scale = self.float_prop(node, "scale", 1.0)?;
                EnvMap::load(&path, scale).with_context(|| self.at(node))?
            }
            "constant" => match self.texture_prop(node, "radiance", Vec3::ONE)? {
                Texture::Constant(c) => EnvMap::constant(c).with_context(|| self.at(node))?,
                _ => return self.fail(node, "constant emitter radiance must be a colour"),
            },
            other => {
                return self.fail(
                    node,
                    format!("unsupported emitter plugin '{other}' (supported: envmap, constant)"),
                )
            }
        };
        let to_world = match self.prop(node, "to_world") {
            Some(t) => Mat3::from_mat4(self.transform(t)?),
            None => Mat3::IDENTITY,
        };
        self.scene.envmap = Some(map.with_to_world(to_world));
        Ok(())
    }

    fn shape(&mut self, node: Node<'a, 'a>) -> Result<()> {
        let ty = node.attribute("type").unwrap_or("");
        let mut mesh = match ty {
            "obj" | "ply" => {
                let filename = self.string_prop(node, "filename")?.ok_or_else(|| anyhow!("{}: missing 'filename'", self.at(node)))?;
                let path = self.path(node, &filename)?;
                load_mesh(&path, self.bool_prop(node, "face_normals", false)?).with_context(|| self.at(node))?
            }
            "rectangle" => Mesh::rectangle(),
            "cube" => Mesh::cube(),
            "sphere" => {
                let center = match self.prop(node, "center") {
                    Some(p) => self.vec3_value(p, 0.0)?,
                    None => Vec3::ZERO,
                };
                Mesh::sphere(center, self.float_prop(node, "radius", 1.0)?, SPHERE_SEGMENTS)
            }
            other => return self.fail(node, format!("unsupported shape plugin '{other}' (supported: obj, ply, rectangle, cube, sphere)")),
        };
        if let Some(t) = self.prop(node, "to_world") {
            let m = self.transform(t)?;
            mesh.transform(m);
            if m.determinant() < 0.0 {
                mesh.reverse_winding();
            }
        }
        if self.bool_prop(node, "flip_normals", false)? {
            mesh.flip_normals();
        }
        let mut material = None;
        for child in node.children().filter(Node::is_element) {
            match child.tag_name().name() {
                "bsdf" => material = Some(self.bsdf(child)?),
                "ref" => match self.named.get(&self.req(child, "id")?) {
                    Some(Named::Material(m)) => material = Some(*m),
                    _ => return self.fail(child, "does not refer to a BSDF declared earlier"),
                },
                "emitter" => {
                    self.scene.warnings.push(format!(
                        "{}: removed this shape: it carries an area emitter, and nprt lights scenes by the environment only (such shapes are usually light portals in a window)",
                        self.at(node)
                    ));
                    return Ok(());
                }
                _ => {}
            }
        }
        mesh.material = match material {
            Some(m) => m,
            None => {
                // Mitsuba's default BSDF: one-sided diffuse, reflectance 0.5.
                let mut m = Material::diffuse("default", Vec3::splat(0.5));
                m.two_sided = false;
                self.scene.materials.push(m);
                self.scene.materials.len() - 1
            }
        };
        mesh.name = format!("{} ({ty})", self.at(node));
        self.scene.meshes.push(mesh);
        Ok(())
    }

    /// Parses a BSDF element into a new scene material; returns its index.
    fn bsdf(&mut self, node: Node<'a, 'a>) -> Result<usize> {
        let material = self.bsdf_material(node)?;
        self.scene.materials.push(material);
        let index = self.scene.materials.len() - 1;
        if let Some(id) = self.attr(node, "id")? {
            self.named.insert(id, Named::Material(index));
        }
        Ok(index)
    }

    /// A BSDF nested in another; one declared with an id is also registered for `<ref>`.
    fn nested_material(&mut self, node: Node<'a, 'a>) -> Result<Material> {
        let material = self.bsdf_material(node)?;
        if let Some(id) = self.attr(node, "id")? {
            self.scene.materials.push(material.clone());
            self.named
                .insert(id, Named::Material(self.scene.materials.len() - 1));
        }
        Ok(material)
    }

    /// The BSDFs a wrapper (twosided, mask, blendbsdf) holds, nested or referenced.
    fn nested_materials(&mut self, node: Node<'a, 'a>) -> Result<Vec<Material>> {
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
    fn single_nested(&mut self, node: Node<'a, 'a>) -> Result<Material> {
        let mut inner = self.nested_materials(node)?;
        if inner.len() != 1 {
            return self.fail(
                node,
                format!("needs exactly one nested BSDF, has {}", inner.len()),
            );
        }
        Ok(inner.remove(0))
    }

    fn bsdf_material(&mut self, node: Node<'a, 'a>) -> Result<Material> {
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
            "conductor" | "roughconductor" => {
                let alpha = if ty == "conductor" { MIN_ALPHA } else { self.microfacet_alpha(node, 0.1)? };
                let ks = self.texture_prop(node, "specular_reflectance", Vec3::ONE)?;
                let material = self.string_prop(node, "material")?;
                let scattering = match (self.prop(node, "eta").is_some() || self.prop(node, "k").is_some(), material.as_deref()) {
                    (false, None | Some("none")) => Scattering::FresnelFree,
                    (true, None) => Scattering::Conductor {
                        eta: self.colour_prop(node, "eta", Vec3::ZERO)?,
                        k: self.colour_prop(node, "k", Vec3::ONE)?,
                    },
                    (true, Some(_)) => return self.fail(node, "give either a material or eta and k, not both"),
                    (false, Some(named)) => match named_conductor(named) {
                        Some((eta, k)) => Scattering::Conductor { eta, k },
                        None => return self.fail(node, format!("unknown conductor material '{named}' (Mitsuba 3 names: {})", conductor_names().collect::<Vec<_>>().join(", "))),
                    },
                };
                let mut m = Material::new(&name, Surface::Direct { kd: Texture::constant(0.0), ks, alpha: Texture::constant(alpha) }, false);
                m.scattering = scattering;
                return Ok(m);
            }
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
            "plastic" | "roughplastic" => {
                let rough = ty == "roughplastic";
                let alpha = if rough { self.microfacet_alpha(node, 0.1)? } else { MIN_ALPHA };
                let kd = self.texture_prop(node, "diffuse_reflectance", Vec3::splat(0.5))?;
                let ks = self.texture_prop(node, "specular_reflectance", Vec3::ONE)?;
                let (d_mean, s_mean) = (kd.mean(), ks.mean());
                let mut m = Material::new(&name, Surface::Direct { kd, ks, alpha: Texture::constant(alpha) }, false);
                m.scattering = Scattering::Plastic {
                    eta: self.relative_ior(node, 1.49)?,
                    rough,
                    nonlinear: self.bool_prop(node, "nonlinear", false)?,
                    sampling_weight: if d_mean + s_mean > 0.0 { s_mean / (d_mean + s_mean) } else { 0.5 },
                };
                return Ok(m);
            }
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

    /// Mitsuba 3's `bumpmap`: one nested texture (the height, whatever its name) and one BSDF.
    fn bump_map(&mut self, node: Node<'a, 'a>, name: String) -> Result<Material> {
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
    fn blend(&mut self, node: Node<'a, 'a>, name: String) -> Result<Material> {
        let w = match self.texture_prop(node, "weight", Vec3::splat(0.5))? {
            Texture::Constant(c) => c.x,
            _ => return self.fail(node, "a textured blend weight is not supported"),
        };
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

    fn microfacet_alpha(&mut self, node: Node<'a, 'a>, default: f32) -> Result<f32> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        std::fs::create_dir_all(dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    const SCENE: &str = r#"<scene version="3.0.0">
  <default name="spp" value="16"/>
  <default name="r" value="0.25"/>
  <integrator type="path"><integer name="max_depth" value="4"/></integrator>
  <sensor type="perspective">
    <float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0, 1, 5" target="0, 1, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="twosided" id="grey"><bsdf type="diffuse"><rgb name="reflectance" value="$r, 0.5, 0.5"/></bsdf></bsdf>
  <shape type="rectangle">
    <transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/><translate y="0.5"/></transform>
    <ref id="grey"/>
  </shape>
  <shape type="cube">
    <bsdf type="roughconductor"><float name="alpha" value="0.2"/><string name="distribution" value="ggx"/></bsdf>
  </shape>
  <emitter type="constant"><rgb name="radiance" value="2"/></emitter>
</scene>"#;

    #[test]
    fn parses_parameters_transforms_and_materials() {
        let dir = std::env::temp_dir().join(format!("nprt-mi-{}", std::process::id()));
        let p = write(&dir, "s.xml", SCENE);
        let opts = SceneOptions {
            set: vec![("r".into(), "0.75".into())],
        };
        let s = load(&p, &opts).unwrap();
        assert_eq!(s.max_depth, Some(4));
        assert_eq!(s.spp, Some(16));
        let cam = s.camera.as_ref().unwrap();
        assert_eq!((cam.width, cam.height), (64, 32));
        assert!((cam.origin() - Vec3::new(0.0, 1.0, 5.0)).length() < 1e-6);
        // Scale, then rotate -90° about X (z=0 plane → y=0 plane facing +Y), then translate.
        let floor = &s.meshes[0];
        assert!(floor
            .positions
            .iter()
            .all(|p| (p.y - 0.5).abs() < 1e-6 && p.x.abs() <= 2.0 + 1e-6));
        assert!((floor.normals[0] - Vec3::Y).length() < 1e-6);
        let m = s.materials[floor.material].eval(Vec2::ZERO);
        assert_eq!(m.kd, Vec3::new(0.75, 0.5, 0.5));
        assert!(s.materials[floor.material].two_sided);
        let metal = s.materials[s.meshes[1].material].eval(Vec2::ZERO);
        assert_eq!((metal.ks, metal.alpha), (Vec3::ONE, 0.2));
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
        assert_eq!(s.envmap.as_ref().unwrap().eval(Vec3::X), Vec3::splat(2.0));
    }

    #[test]
    fn errors_name_file_line_and_element() {
        let dir = std::env::temp_dir().join(format!("nprt-mi-err-{}", std::process::id()));
        let bad = SCENE.replace(r#"<bsdf type="roughconductor">"#, r#"<bsdf type="hair">"#);
        let p = write(&dir, "bad.xml", &bad);
        let err = format!("{:#}", load(&p, &SceneOptions::default()).unwrap_err());
        assert!(err.contains("bad.xml:17:") && err.contains("hair"), "{err}");

        let p = write(
            &dir,
            "missing.xml",
            &SCENE.replace(
                r#"<shape type="cube">"#,
                r#"<shape type="ply"><string name="filename" value="nope.ply"/>"#,
            ),
        );
        let err = format!("{:#}", load(&p, &SceneOptions::default()).unwrap_err());
        assert!(
            err.contains("nope.ply") && err.contains("does not exist"),
            "{err}"
        );

        let opts = SceneOptions {
            set: vec![("unknown".into(), "1".into())],
        };
        let err = format!(
            "{:#}",
            load(&write(&dir, "ok.xml", SCENE), &opts).unwrap_err()
        );
        assert!(err.contains("no parameter 'unknown'"), "{err}");

        let p = write(&dir, "unset.xml", &SCENE.replace("$spp", "$nosuch"));
        let err = format!("{:#}", load(&p, &SceneOptions::default()).unwrap_err());
        assert!(err.contains("$nosuch"), "{err}");
        // Values that are not finite numbers (1e40 overflows f32) stop at the file and line.
        for v in ["nan", "inf", "-inf", "1e40", "1, nan, 1"] {
            let bad = SCENE.replace(
                r#"<rgb name="radiance" value="2"/>"#,
                &format!(r#"<rgb name="radiance" value="{v}"/>"#),
            );
            let err = format!(
                "{:#}",
                load(
                    &write(&dir, "nonfinite.xml", &bad),
                    &SceneOptions::default()
                )
                .unwrap_err()
            );
            assert!(
                err.contains("nonfinite.xml:19:") && err.contains("not a finite number"),
                "{v}: {err}"
            );
        }
    }

    #[test]
    fn mitsuba_0x_property_names_upgrade_as_mitsuba_3() {
        for (old, new) in [
            ("toWorld", "to_world"),
            ("maxDepth", "max_depth"),
            ("intIOR", "int_ior"),
            ("specularReflectance", "specular_reflectance"),
            ("fovAxis", "fov_axis"),
            ("uoffset", "uoffset"),
            ("to_world", "to_world"),
        ] {
            assert_eq!(snake_case(old), new);
        }
    }

    /// A scene in Bitterli's Mitsuba 0.5 style: camelCase names, glass, a mask over a nested
    /// BSDF declared with an id, a bump-map wrapper nobody references, complex-index copper and
    /// a light portal (a black rectangle carrying an area emitter).
    #[test]
    fn loads_mitsuba_0_5_scenes_with_glass_masks_and_portals() {
        let text = r#"<scene version="0.5.0">
  <integrator type="path"><integer name="maxDepth" value="7"/></integrator>
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="toWorld"><lookAt origin="0, 1, 5" target="0, 1, 0" up="0, 1, 0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="8"/></sampler>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="16"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="dielectric" id="Glass"><float name="intIOR" value="1.5"/><float name="extIOR" value="1"/>
    <rgb name="specularTransmittance" value="0, 0, 0"/></bsdf>
  <bsdf type="thindielectric" id="Pane"><string name="intIOR" value="bk7"/></bsdf>
  <bsdf type="mask" id="Blinds"><spectrum name="opacity" value="0.6"/>
    <bsdf type="twosided"><bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.6, 0.5, 0.4"/></bsdf></bsdf></bsdf>
  <bsdf type="bumpmap"><float name="scale" value="1"/>
    <bsdf type="twosided" id="Cushion"><bsdf type="diffuse"><rgb name="reflectance" value="0.5, 0.1, 0.1"/></bsdf></bsdf></bsdf>
  <bsdf type="twosided" id="Copper"><bsdf type="roughconductor"><float name="alpha" value="0.1"/>
    <string name="distribution" value="ggx"/>
    <rgb name="eta" value="0.2, 0.92, 1.1"/><rgb name="k" value="3.9, 2.45, 2.14"/></bsdf></bsdf>
  <shape type="rectangle"><ref id="Glass"/></shape>
  <shape type="rectangle"><ref id="Pane"/></shape>
  <shape type="rectangle"><ref id="Blinds"/></shape>
  <shape type="rectangle"><ref id="Cushion"/></shape>
  <shape type="rectangle"><ref id="Copper"/></shape>
  <shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>
    <emitter type="area"><spectrum name="radiance" value="16"/></emitter></shape>
</scene>"#;
        let s = parse(
            text,
            Path::new("kitchen-like.xml"),
            &SceneOptions::default(),
        )
        .unwrap();
        assert_eq!((s.max_depth, s.spp), (Some(7), Some(8)));
        assert!((s.camera.as_ref().unwrap().origin() - Vec3::new(0.0, 1.0, 5.0)).length() < 1e-6);
        assert_eq!(s.meshes.len(), 5, "the portal is removed");
        let at = |i: usize| {
            let m = &s.materials[s.meshes[i].material];
            (m, m.eval(Vec2::ZERO))
        };
        let (glass, g) = at(0);
        assert_eq!(
            g.scattering,
            Scattering::Dielectric {
                eta: 1.5,
                thin: false
            }
        );
        assert!(!glass.two_sided && g.kt == Vec3::ZERO && g.ks == Vec3::ONE);
        let (kd, ks, alpha) = g.gbuffer();
        assert!(kd == Vec3::ZERO && (ks - Vec3::splat(0.04)).abs().max_element() < 1e-6);
        assert_eq!(alpha, MIN_ALPHA);
        let (_, pane) = at(1);
        assert!(
            matches!(pane.scattering, Scattering::Dielectric { eta, thin: true } if (eta - 1.5046 / 1.000277).abs() < 1e-6)
        );
        let (blinds, b) = at(2);
        assert!(blinds.two_sided && (b.opacity - 0.6).abs() < 1e-6);
        assert_eq!(b.kd, Vec3::new(0.6, 0.5, 0.4));
        assert!((b.gbuffer().0 - Vec3::new(0.36, 0.3, 0.24)).length() < 1e-6);
        assert_eq!(at(3).1.kd, Vec3::new(0.5, 0.1, 0.1));
        let (copper, c) = at(4);
        assert!(copper.two_sided && c.alpha == 0.1);
        let f0 = c.gbuffer().1;
        assert!(
            f0.x > f0.y && f0.y > f0.z && f0.x < 1.0,
            "copper's F0 is reddish: {f0}"
        );
        assert!(s.warnings.iter().any(|w| w.contains("area emitter")));
        assert!(s.warnings.iter().any(|w| w.contains("without an id")));

        // Used by a shape, a bump map needs its height texture, and records which wrapper is
        // outside: twosided(bumpmap(…)) mirrors the bumps seen from behind.
        let with = |shape: &str| {
            let t = text.replace(r#"<ref id="Cushion"/>"#, shape);
            parse(&t, Path::new("k.xml"), &SceneOptions::default())
        };
        let err = with(r#"<bsdf type="bumpmap"><bsdf type="diffuse"/></bsdf>"#).unwrap_err();
        assert!(
            format!("{err:#}").contains("k.xml:")
                && format!("{err:#}").contains("needs exactly one nested texture"),
            "{err:#}"
        );
        let checker = r#"<texture type="checkerboard" name="map"/>"#;
        for (shape, two_sided, mirrored) in [
            (
                format!(
                    r#"<bsdf type="bumpmap"><float name="scale" value="0.3"/>{checker}<bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf>"#
                ),
                true,
                false,
            ),
            (
                format!(
                    r#"<bsdf type="twosided"><bsdf type="bumpmap">{checker}<bsdf type="diffuse"/></bsdf></bsdf>"#
                ),
                true,
                true,
            ),
            (
                format!(r#"<bsdf type="bumpmap">{checker}<bsdf type="diffuse"/></bsdf>"#),
                false,
                false,
            ),
        ] {
            let s = with(&shape).unwrap();
            let m = &s.materials[s.meshes[3].material];
            let bump = m.bump.as_ref().expect("bumped");
            assert_eq!(
                (m.two_sided, bump.mirrored_behind),
                (two_sided, mirrored),
                "{shape}"
            );
            assert!(matches!(bump.height, Texture::Checkerboard { .. }));
            assert_eq!(bump.scale, if shape.contains("0.3") { 0.3 } else { 1.0 });
        }
        let err = with(&format!(r#"<bsdf type="bumpmap">{checker}<bsdf type="mask"><bsdf type="diffuse"/></bsdf></bsdf>"#)).unwrap_err();
        assert!(
            format!("{err:#}").contains("mask inside a bump map"),
            "{err:#}"
        );
        // Conductors named as in Mitsuba 3 take its complex index; unknown names are refused.
        let named = |m: &str| {
            with(&format!(
                r#"<bsdf type="roughconductor"><string name="material" value="{m}"/></bsdf>"#
            ))
        };
        let s = named("Au").unwrap();
        assert_eq!(
            s.materials[s.meshes[3].material].scattering,
            Scattering::Conductor {
                eta: named_conductor("Au").unwrap().0,
                k: named_conductor("Au").unwrap().1
            }
        );
        let err = named("Unobtainium").unwrap_err();
        assert!(
            format!("{err:#}").contains("unknown conductor material 'Unobtainium'")
                && format!("{err:#}").contains("Cu_palik"),
            "{err:#}"
        );
        // Mitsuba 3 names are not renamed in a 0.x file's camelCase world, nor the reverse.
        let v3 = text.replace("0.5.0", "3.0.0");
        let s3 = parse(&v3, Path::new("k.xml"), &SceneOptions::default()).unwrap();
        assert_eq!(
            s3.max_depth, None,
            "maxDepth means nothing to a version-3 file"
        );
    }
}
