//! Mitsuba XML scenes, the subset DESIGN.md lists: obj/ply/rectangle/cube/sphere shapes;
//! diffuse/conductor/roughconductor (RGB or named index)/plastic/roughplastic/dielectric/
//! thindielectric/twosided/mask/bumpmap (and diffuse+conductor `blendbsdf`) BSDFs;
//! bitmap/checkerboard textures; envmap/constant emitters; a perspective sensor with hdrfilm and
//! sampler; the path integrator; `<default>`, `$name` and `<ref>`. Files of format version 0.x
//! (Mitsuba 0.5/0.6, e.g. Bitterli's scenes) are upgraded as Mitsuba 3 upgrades them: camelCase
//! property names, a diffuse BSDF's `diffuseReflectance`, texture `uscale`/`uoffset`. Shapes
//! carrying an area emitter are removed with a warning (the scene is lit by its environment only).
//! Anything else stops with an error naming the file, line and element.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context, Result};
use glam::Vec3;
use roxmltree::{Document, Node};

use crate::scene::Scene;
use crate::scene_options::SceneOptions;
use crate::texture::{Bitmap, Texture};

mod bsdf;
mod emitter;
mod sensor;
mod shape;
#[cfg(test)]
mod tests;
mod texture;
mod transform;
mod upgrade;

use upgrade::snake_case;

pub fn load(path: &Path, opts: &SceneOptions) -> Result<Scene> {
    let text = nprt_io::read_input_string(path)
        .with_context(|| format!("cannot read scene file '{}'", path.display()))?;
    parse(&text, path, opts)
}

/// How deep elements may nest. Real scenes nest a few levels (a two-sided blend of bump-mapped
/// BSDFs with textures is under 10); the reader recurses per level, so without a bound a
/// hostile file (3000 nested `<bsdf>`) overflowed the stack.
const MAX_NESTING: usize = 100;

/// Refuses a document nested deeper than [`MAX_NESTING`], naming the first element too deep.
fn check_nesting(doc: &Document, file: &str) -> Result<()> {
    // Depth by node id, filled in document order (a parent comes before its children).
    let mut depth = vec![0usize; doc.descendants().count() + 1];
    for node in doc.descendants() {
        let d = node
            .parent()
            .map_or(0, |p| depth[p.id().get() as usize] + 1);
        depth[node.id().get() as usize] = d;
        if d > MAX_NESTING {
            bail!(
                "{}: elements nest more than {MAX_NESTING} levels deep",
                pos(file, doc, node)
            );
        }
    }
    Ok(())
}

/// Parses the Mitsuba scene `text` of the file `path` (which names it in errors and anchors
/// its relative file references).
pub fn parse(text: &str, path: &Path, opts: &SceneOptions) -> Result<Scene> {
    let file = path.display().to_string();
    let doc =
        Document::parse(text).map_err(|e| anyhow!("scene file '{file}' is not valid XML: {e}"))?;
    check_nesting(&doc, &file)?;
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
        lighting_replaced: opts.lighting_replaced,
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
    /// The caller lights the scene with its own map: emitters are not read.
    lighting_replaced: bool,
}

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
}
