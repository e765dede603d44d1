// A scene's surfaces on the device, as nprt-trace's surface_point and nprt-scene's materials
// make them: the point a ray hits on a triangle (interpolated position and normal, uv
// derivatives, two-sided flip, bump map) and the material's parameters there. The records'
// layouts are gpu_scene.rs's; the shader that includes this binds them as `positions`,
// `attributes`, `triangles`, `materials`, `textures` and `bitmaps`. Shared by the G-buffer and
// the path tracer. After lerp.wgsl.

const TWO_SIDED: u32 = 1u;
const BUMP: u32 = 2u;
const BUMP_MIRRORED_BEHIND: u32 = 4u;
const OPACITY: u32 = 8u;
const METALLIC_ROUGHNESS: u32 = 16u;
const HAS_NORMALS: u32 = 1u;
const HAS_UVS: u32 = 2u;
const CONSTANT: u32 = 0u;
const BITMAP: u32 = 1u;
const MIN_ALPHA: f32 = 1e-3;
const MATERIAL_WORDS: u32 = 32u;
const TEXTURE_WORDS: u32 = 16u;

fn position(v: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

fn normal_of(v: u32) -> vec3<f32> {
    return vec3<f32>(attributes[5u * v], attributes[5u * v + 1u], attributes[5u * v + 2u]);
}

fn uv_of(v: u32) -> vec2<f32> {
    return vec2<f32>(attributes[5u * v + 3u], attributes[5u * v + 4u]);
}

// glam's normalize_or: `v` scaled to unit length, or `fallback` where that is not finite.
fn normalize_or(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let r = 1.0 / length(v);
    if r > 0.0 && r < 3.4e38 {
        return v * r;
    }
    return fallback;
}

fn luminance(c: vec3<f32>) -> f32 {
    return 0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z;
}

fn tex_float(t: u32, k: u32) -> f32 {
    return bitcast<f32>(textures[TEXTURE_WORDS * t + k]);
}

fn tex_vec3(t: u32, k: u32) -> vec3<f32> {
    return vec3<f32>(tex_float(t, k), tex_float(t, k + 1u), tex_float(t, k + 2u));
}

// The texture's uv transform applied to `uv` (glam's Affine2::transform_point2).
fn to_uv(t: u32, uv: vec2<f32>) -> vec2<f32> {
    let x_axis = vec2<f32>(tex_float(t, 10u), tex_float(t, 11u));
    let y_axis = vec2<f32>(tex_float(t, 12u), tex_float(t, 13u));
    let shift = vec2<f32>(tex_float(t, 14u), tex_float(t, 15u));
    return x_axis * uv.x + y_axis * uv.y + shift;
}

// Texel (x, y) of bitmap texture `t`, wrapped (repeat).
fn bitmap_texel(t: u32, x: i32, y: i32) -> vec3<f32> {
    let w = i32(textures[TEXTURE_WORDS * t + 2u]);
    let h = i32(textures[TEXTURE_WORDS * t + 3u]);
    let xi = ((x % w) + w) % w;
    let yi = ((y % h) + h) % h;
    let k = 3u * (textures[TEXTURE_WORDS * t + 1u] + u32(yi * w + xi));
    return vec3<f32>(bitmaps[k], bitmaps[k + 1u], bitmaps[k + 2u]);
}

// Bilinear footprint of `p` (texel centres at half-integers): the texel at or before it and
// the weights of the next one in x and y.
struct Footprint {
    x0: i32,
    y0: i32,
    f: vec2<f32>,
}

fn footprint(t: u32, p: vec2<f32>) -> Footprint {
    let w = f32(textures[TEXTURE_WORDS * t + 2u]);
    let h = f32(textures[TEXTURE_WORDS * t + 3u]);
    let q = vec2<f32>(p.x * w - 0.5, p.y * h - 0.5);
    let q0 = floor(q);
    return Footprint(i32(q0.x), i32(q0.y), q - q0);
}

// Texture::eval.
fn texture(t: u32, uv: vec2<f32>) -> vec3<f32> {
    let kind = textures[TEXTURE_WORDS * t];
    let colour = tex_vec3(t, 4u);
    if kind == CONSTANT {
        return colour;
    }
    let p = to_uv(t, uv);
    if kind == BITMAP {
        let b = footprint(t, p);
        let top = lerp(bitmap_texel(t, b.x0, b.y0), bitmap_texel(t, b.x0 + 1, b.y0), b.f.x);
        let bottom = lerp(bitmap_texel(t, b.x0, b.y0 + 1), bitmap_texel(t, b.x0 + 1, b.y0 + 1), b.f.x);
        return colour * lerp(top, bottom, b.f.y);
    }
    let f = p - floor(p);
    if (f.x > 0.5) == (f.y > 0.5) {
        return colour;
    }
    return tex_vec3(t, 7u);
}

// Texture::luminance_gradient: the bitmap's bilinear luminance derivative through its uv
// transform; zero for constants and checkerboards.
fn luminance_gradient(t: u32, uv: vec2<f32>) -> vec2<f32> {
    if textures[TEXTURE_WORDS * t] != BITMAP {
        return vec2<f32>(0.0);
    }
    let b = footprint(t, to_uv(t, uv));
    let f00 = luminance(bitmap_texel(t, b.x0, b.y0));
    let f10 = luminance(bitmap_texel(t, b.x0 + 1, b.y0));
    let f01 = luminance(bitmap_texel(t, b.x0, b.y0 + 1));
    let f11 = luminance(bitmap_texel(t, b.x0 + 1, b.y0 + 1));
    let d = vec2<f32>(
        (1.0 - b.f.y) * (f10 - f00) + b.f.y * (f11 - f01),
        (1.0 - b.f.x) * (f01 - f00) + b.f.x * (f11 - f10),
    );
    let x_axis = vec2<f32>(tex_float(t, 10u), tex_float(t, 11u));
    let y_axis = vec2<f32>(tex_float(t, 12u), tex_float(t, 13u));
    let size = vec2<f32>(f32(textures[TEXTURE_WORDS * t + 2u]), f32(textures[TEXTURE_WORDS * t + 3u]));
    return vec2<f32>(dot(x_axis, d), dot(y_axis, d)) * size * luminance(tex_vec3(t, 4u));
}

fn material_word(m: u32, k: u32) -> u32 {
    return materials[MATERIAL_WORDS * m + k];
}

// Frame3::new's tangent pair of a unit normal (Duff et al.).
fn tangents(n: vec3<f32>) -> array<vec3<f32>, 2> {
    // copysign(1, n.z): −0 counts as negative.
    let sign = select(1.0, -1.0, (bitcast<u32>(n.z) & 0x80000000u) != 0u);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return array<vec3<f32>, 2>(
        vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        vec3<f32>(b, sign + n.y * n.y * a, -n.y),
    );
}

// The point of triangle `tri` at barycentrics (b1, b2) seen along `dir`, as surface_point.
struct SurfacePoint {
    p: vec3<f32>,
    // Geometric normal, on the side of the unbumped shading normal.
    ng: vec3<f32>,
    ns: vec3<f32>,
    // The shading normal before the bump map (ns where there is none).
    unbumped: vec3<f32>,
    bumped: bool,
    material: u32,
    uv: vec2<f32>,
}

fn surface_point(tri: u32, b1: f32, b2: f32, dir: vec3<f32>) -> SurfacePoint {
    let i0 = triangles[4u * tri];
    let i1 = triangles[4u * tri + 1u];
    let i2 = triangles[4u * tri + 2u];
    let packed = triangles[4u * tri + 3u];
    let v0 = position(i0);
    let v1 = position(i1);
    let v2 = position(i2);
    let w = vec3<f32>(1.0 - b1 - b2, b1, b2);
    let p = v0 * w.x + v1 * w.y + v2 * w.z;
    let face = normalize_or(cross(v1 - v0, v2 - v0), vec3<f32>(0.0, 1.0, 0.0));
    var ns = face;
    if (packed & HAS_NORMALS) != 0u {
        ns = normalize_or(normal_of(i0) * w.x + normal_of(i1) * w.y + normal_of(i2) * w.z, face);
    }
    var uv = vec2<f32>(b1, b2);
    var dp_du = v1 - v0;
    var dp_dv = v2 - v0;
    if (packed & HAS_UVS) != 0u {
        let t0 = uv_of(i0);
        let t1 = uv_of(i1);
        let t2 = uv_of(i2);
        uv = t0 * w.x + t1 * w.y + t2 * w.z;
        let duv0 = t1 - t0;
        let duv1 = t2 - t0;
        let dp0 = v1 - v0;
        let dp1 = v2 - v0;
        let det = duv0.x * duv1.y - duv0.y * duv1.x;
        if det != 0.0 {
            dp_du = (dp0 * duv1.y - dp1 * duv0.y) / det;
            dp_dv = (dp1 * duv0.x - dp0 * duv1.x) / det;
        } else {
            let f = tangents(face);
            dp_du = f[0];
            dp_dv = f[1];
        }
    }
    let m = packed >> 2u;
    let flags = material_word(m, 0u);
    let behind = (flags & TWO_SIDED) != 0u && dot(ns, dir) > 0.0;
    var base = ns;
    let bumped = (flags & BUMP) != 0u;
    if bumped {
        let g = bitcast<f32>(material_word(m, 6u)) * luminance_gradient(material_word(m, 5u), uv);
        let du = dp_du + ns * (g.x - dot(ns, dp_du));
        let dv = dp_dv + ns * (g.y - dot(ns, dp_dv));
        var nb = normalize_or(cross(du, dv), ns);
        if dot(nb, face) < 0.0 {
            nb = -nb;
        }
        var n = nb;
        if behind {
            base = -ns;
            if (flags & BUMP_MIRRORED_BEHIND) != 0u {
                n = nb - 2.0 * dot(nb, ns) * ns;
            } else {
                n = -nb;
            }
        }
        // Mitsuba's flip_invalid_normals.
        if dot(dir, base) * dot(dir, n) <= 0.0 {
            n = 2.0 * dot(n, base) * base - n;
        }
        ns = n;
    } else if behind {
        ns = -ns;
        base = ns;
    }
    let ng = select(face, -face, dot(face, base) < 0.0);
    return SurfacePoint(p, ng, ns, base, bumped, m, uv);
}

// Material::eval at `uv`: kd, ks (before any Fresnel term), α, the glass's kt and the mask's
// opacity.
struct MaterialParams {
    kd: vec3<f32>,
    ks: vec3<f32>,
    alpha: f32,
    kt: vec3<f32>,
    opacity: f32,
}

fn material_params(m: u32, uv: vec2<f32>) -> MaterialParams {
    let flags = material_word(m, 0u);
    var kd: vec3<f32>;
    var ks: vec3<f32>;
    var alpha: f32;
    if (flags & METALLIC_ROUGHNESS) != 0u {
        let b = texture(material_word(m, 1u), uv);
        let mr = texture(material_word(m, 2u), uv);
        let rough = clamp(mr.y, 0.0, 1.0);
        let metal = clamp(mr.z, 0.0, 1.0);
        kd = b * (1.0 - metal);
        ks = lerp(vec3<f32>(0.04), b, metal);
        alpha = max(rough * rough, MIN_ALPHA);
    } else {
        kd = texture(material_word(m, 1u), uv);
        ks = texture(material_word(m, 2u), uv);
        alpha = max(texture(material_word(m, 3u), uv).x, MIN_ALPHA);
    }
    var opacity = 1.0;
    if (flags & OPACITY) != 0u {
        opacity = clamp(luminance(texture(material_word(m, 4u), uv)), 0.0, 1.0);
    }
    let kt = texture(material_word(m, 20u), uv);
    return MaterialParams(kd, ks, alpha, kt, opacity);
}
