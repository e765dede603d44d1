// nprt-trace's Bsdf on the device, in a local shading frame (z = normal), with its GGX
// distribution, Fresnel terms and plastic coat: eval (f·cos θi), pdf and sample, as the CPU
// evaluates and samples them, so that the path tracer here and there estimate the same
// integral. Materials' scattering words: gpu_scene.rs. After map_lookup.wgsl (PI) and
// surface.wgsl.

const FRESNEL_FREE: u32 = 0u;
const CONDUCTOR: u32 = 1u;
const DIELECTRIC: u32 = 2u;
const PLASTIC: u32 = 3u;
const THIN: u32 = 1u;
const NONLINEAR: u32 = 2u;

struct Bsdf {
    kd: vec3<f32>,
    ks: vec3<f32>,
    alpha: f32,
    kt: vec3<f32>,
    opacity: f32,
    kind: u32,
    flags: u32,
    eta: f32,
    conductor_eta: vec3<f32>,
    conductor_k: vec3<f32>,
    // The plastic's coat record in `materials` (0: none, then it scatters as the model).
    coat: u32,
    p_spec: f32,
    bumped: bool,
    // The normal before the bump map, in the (bumped) shading frame.
    unbumped: vec3<f32>,
}

fn material_float(m: u32, k: u32) -> f32 {
    return bitcast<f32>(material_word(m, k));
}

fn material_vec3(m: u32, k: u32) -> vec3<f32> {
    return vec3<f32>(material_float(m, k), material_float(m, k + 1u), material_float(m, k + 2u));
}

// Bsdf::new and with_bump for material `m` with parameters `mp`; `unbumped` in the local frame.
fn make_bsdf(m: u32, mp: MaterialParams, bumped: bool, unbumped: vec3<f32>) -> Bsdf {
    let kind = material_word(m, 10u);
    var coat = 0u;
    if kind == PLASTIC {
        coat = material_word(m, 21u);
    }
    var p_spec = 0.0;
    if kind == PLASTIC {
        p_spec = material_float(m, 13u);
    } else {
        let ld = luminance(mp.kd);
        let ls = luminance(mp.ks);
        if ld + ls > 0.0 {
            p_spec = ls / (ld + ls);
        }
    }
    return Bsdf(mp.kd, mp.ks, mp.alpha, mp.kt, mp.opacity, kind, material_word(m, 11u),
        material_float(m, 12u), material_vec3(m, 14u), material_vec3(m, 17u), coat, p_spec,
        bumped, unbumped);
}

// GgxDistribution.
fn ggx_d(alpha: f32, m: vec3<f32>) -> f32 {
    let a2 = alpha * alpha;
    let c2 = m.z * m.z;
    let denom = c2 * (a2 - 1.0) + 1.0;
    return a2 / (PI * denom * denom);
}

fn ggx_g1(alpha: f32, v: vec3<f32>, m: vec3<f32>) -> f32 {
    if dot(v, m) * v.z <= 0.0 {
        return 0.0;
    }
    let c2 = v.z * v.z;
    let tan2 = max((1.0 - c2) / c2, 0.0);
    return 2.0 / (1.0 + sqrt(1.0 + alpha * alpha * tan2));
}

fn ggx_sample_visible(alpha: f32, wo: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(alpha * wo.x, alpha * wo.y, wo.z));
    let len2 = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if len2 > 0.0 {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) / sqrt(len2);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * r * sin(phi);
    let nh = t1 * p1 + t2 * p2 + vh * sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0));
    return normalize(vec3<f32>(alpha * nh.x, alpha * nh.y, max(nh.z, 1e-6)));
}

// fresnel_dielectric: (r, cos θt, η_it, η_ti).
fn fresnel_dielectric(cos_i: f32, eta: f32) -> vec4<f32> {
    let outside = cos_i >= 0.0;
    var eta_it = 1.0 / eta;
    var eta_ti = eta;
    if outside {
        eta_it = eta;
        eta_ti = 1.0 / eta;
    }
    let cos_t_sqr = 1.0 - (1.0 - cos_i * cos_i) * eta_ti * eta_ti;
    let ci = abs(cos_i);
    let ct = sqrt(max(cos_t_sqr, 0.0));
    var r = 0.0;
    if eta != 1.0 {
        if ci == 0.0 {
            r = 1.0;
        } else {
            let a_s = (ci - eta_it * ct) / (ci + eta_it * ct);
            let a_p = (ct - eta_it * ci) / (ct + eta_it * ci);
            r = 0.5 * (a_s * a_s + a_p * a_p);
        }
    }
    return vec4<f32>(r, select(ct, -ct, outside), eta_it, eta_ti);
}

fn fresnel_conductor(cos_i: f32, eta: vec3<f32>, k: vec3<f32>) -> vec3<f32> {
    let c2 = cos_i * cos_i;
    let s2 = 1.0 - c2;
    let s4 = s2 * s2;
    let temp1 = eta * eta - k * k - vec3<f32>(s2);
    let a2pb2 = sqrt(max(temp1 * temp1 + 4.0 * k * k * eta * eta, vec3<f32>(0.0)));
    let a = sqrt(max(0.5 * (a2pb2 + temp1), vec3<f32>(0.0)));
    let term1 = a2pb2 + vec3<f32>(c2);
    let term2 = 2.0 * cos_i * a;
    let r_s = (term1 - term2) / (term1 + term2);
    let term3 = a2pb2 * c2 + vec3<f32>(s4);
    let term4 = term2 * s2;
    let r_p = r_s * (term3 - term4) / (term3 + term4);
    return 0.5 * (r_s + r_p);
}

fn coat_is_rough(b: Bsdf) -> bool {
    return materials[b.coat + 1u] == 1u;
}

// Coating::transmittance.
fn coat_transmittance(b: Bsdf, cos: f32) -> f32 {
    if !coat_is_rough(b) {
        return 1.0 - fresnel_dielectric(cos, b.eta).x;
    }
    let x = clamp(cos, 0.0, 1.0) * 63.0;
    let i = min(u32(x), 62u);
    let t0 = bitcast<f32>(materials[b.coat + 2u + i]);
    let t1 = bitcast<f32>(materials[b.coat + 3u + i]);
    return t0 + (t1 - t0) * (x - f32(i));
}

fn is_glass(b: Bsdf) -> bool {
    return b.kind == DIELECTRIC;
}

fn has_coat(b: Bsdf) -> bool {
    return b.coat != 0u;
}

fn any_nonzero(v: vec3<f32>) -> bool {
    return any(v != vec3<f32>(0.0));
}

fn scatters(b: Bsdf, wo: vec3<f32>) -> bool {
    if b.opacity < 1.0 {
        return true;
    }
    if is_glass(b) {
        return any_nonzero(b.ks) || any_nonzero(b.kt);
    }
    return wo.z > 0.0 && (any_nonzero(b.kd) || any_nonzero(b.ks));
}

fn is_smooth(b: Bsdf) -> bool {
    return !is_glass(b) && b.opacity > 0.0;
}

fn bump_factor(b: Bsdf, wi: vec3<f32>) -> f32 {
    if !b.bumped {
        return 1.0;
    }
    let n = b.unbumped;
    let c = dot(wi, n);
    if c * wi.z <= 0.0 {
        return 0.0;
    }
    let tan2_n = max(1.0 - n.z * n.z, 0.0) / (n.z * n.z);
    let tan2_c = max(1.0 - c * c, 0.0) / (c * c);
    let a2 = min(0.125 * tan2_n, 1.0);
    return 2.0 / (1.0 + sqrt(1.0 + a2 * tan2_c));
}

fn specular_probability(b: Bsdf, wo: vec3<f32>) -> f32 {
    if !has_coat(b) {
        return b.p_spec;
    }
    let reflected = 1.0 - coat_transmittance(b, wo.z);
    let s = reflected * b.p_spec;
    let d = (1.0 - reflected) * (1.0 - b.p_spec);
    if s + d > 0.0 {
        return s / (s + d);
    }
    return 0.0;
}

fn eval_surface(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if wo.z <= 0.0 || wi.z <= 0.0 || is_glass(b) {
        return vec3<f32>(0.0);
    }
    var diffuse = b.kd;
    var fresnel = vec3<f32>(1.0);
    if has_coat(b) {
        let internal_reflectance = bitcast<f32>(materials[b.coat]);
        var internal = vec3<f32>(internal_reflectance);
        if (b.flags & NONLINEAR) != 0u {
            internal = b.kd * internal_reflectance;
        }
        let base = b.kd / (vec3<f32>(1.0) - internal);
        let through = coat_transmittance(b, wo.z) * coat_transmittance(b, wi.z) / (b.eta * b.eta);
        var specular = 0.0;
        if coat_is_rough(b) {
            specular = fresnel_dielectric(dot(wo, normalize(wo + wi)), b.eta).x;
        }
        diffuse = base * through;
        fresnel = vec3<f32>(specular);
    } else if b.kind == CONDUCTOR {
        fresnel = fresnel_conductor(dot(wo, normalize(wo + wi)), b.conductor_eta, b.conductor_k);
    }
    var f = diffuse * (wi.z / PI);
    if b.p_spec > 0.0 && any_nonzero(fresnel) {
        let m = normalize(wo + wi);
        let g = ggx_g1(b.alpha, wo, m) * ggx_g1(b.alpha, wi, m);
        f += b.ks * fresnel * (ggx_d(b.alpha, m) * g / (4.0 * wo.z));
    }
    return f;
}

fn pdf_surface(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 || is_glass(b) {
        return 0.0;
    }
    let p_spec = specular_probability(b, wo);
    var pdf = (1.0 - p_spec) * wi.z / PI;
    if p_spec > 0.0 && (!has_coat(b) || coat_is_rough(b)) {
        let m = normalize(wo + wi);
        pdf += p_spec * ggx_g1(b.alpha, wo, m) * ggx_d(b.alpha, m) / (4.0 * wo.z);
    }
    return pdf;
}

fn bsdf_eval(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    return eval_surface(b, wo, wi) * (b.opacity * bump_factor(b, wi));
}

fn bsdf_pdf(b: Bsdf, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if bump_factor(b, wi) == 0.0 {
        return 0.0;
    }
    return pdf_surface(b, wo, wi) * b.opacity;
}

// BsdfSample; `ok` false where none was drawn.
struct BsdfSample {
    wi: vec3<f32>,
    weight: vec3<f32>,
    pdf: f32,
    delta: bool,
    eta: f32,
    ok: bool,
}

fn no_sample() -> BsdfSample {
    return BsdfSample(vec3<f32>(0.0), vec3<f32>(0.0), 0.0, false, 1.0, false);
}

fn sample_reflection(b: Bsdf, wo: vec3<f32>, u: vec2<f32>, u_lobe: f32) -> BsdfSample {
    if wo.z <= 0.0 {
        return no_sample();
    }
    let p_spec = specular_probability(b, wo);
    var wi: vec3<f32>;
    if u_lobe >= p_spec {
        let r = sqrt(u.x);
        let phi = 2.0 * PI * u.y;
        wi = vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u.x, 0.0)));
    } else {
        if has_coat(b) && !coat_is_rough(b) {
            // A smooth coat's delta reflection.
            let weight = b.ks * (fresnel_dielectric(wo.z, b.eta).x / p_spec);
            return BsdfSample(vec3<f32>(-wo.x, -wo.y, wo.z), weight, p_spec, true, 1.0, true);
        }
        let m = ggx_sample_visible(b.alpha, wo, u);
        wi = 2.0 * dot(wo, m) * m - wo;
    }
    let pdf = pdf_surface(b, wo, wi);
    if pdf <= 0.0 {
        return no_sample();
    }
    return BsdfSample(wi, eval_surface(b, wo, wi) / pdf, pdf, false, 1.0, true);
}

fn sample_glass(b: Bsdf, wo: vec3<f32>, u_lobe: f32) -> BsdfSample {
    let reflect = vec3<f32>(-wo.x, -wo.y, wo.z);
    var r: f32;
    var wt: vec3<f32>;
    var weight_t: vec3<f32>;
    var eta_t: f32;
    if (b.flags & THIN) != 0u {
        let r0 = fresnel_dielectric(abs(wo.z), b.eta).x;
        r = r0 * 2.0 / (1.0 + r0);
        wt = -wo;
        weight_t = b.kt;
        eta_t = 1.0;
    } else {
        let f = fresnel_dielectric(wo.z, b.eta);
        r = f.x;
        wt = vec3<f32>(-f.w * wo.x, -f.w * wo.y, f.y);
        weight_t = b.kt * (f.w * f.w);
        eta_t = f.z;
    }
    var s = BsdfSample(wt, weight_t, 1.0 - r, true, eta_t, true);
    if u_lobe <= r {
        s = BsdfSample(reflect, b.ks, r, true, 1.0, true);
    }
    s.ok = s.pdf > 0.0 && any_nonzero(s.weight);
    return s;
}

fn bsdf_sample(b: Bsdf, wo: vec3<f32>, u: vec2<f32>, u_lobe_in: f32) -> BsdfSample {
    if !scatters(b, wo) {
        return no_sample();
    }
    if u_lobe_in >= b.opacity {
        return BsdfSample(-wo, vec3<f32>(1.0), 1.0 - b.opacity, true, 1.0, true);
    }
    let u_lobe = u_lobe_in / b.opacity;
    var s: BsdfSample;
    if is_glass(b) {
        s = sample_glass(b, wo, u_lobe);
    } else {
        s = sample_reflection(b, wo, u, u_lobe);
    }
    if !s.ok {
        return s;
    }
    let bump = bump_factor(b, s.wi);
    if bump == 0.0 {
        return no_sample();
    }
    s.weight *= bump;
    s.pdf *= b.opacity;
    return s;
}
