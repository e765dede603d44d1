//! Distant lighting: an equirectangular (lat-long) environment map with Mitsuba 3's `envmap`
//! mapping and filtering, rotated about +Y, importance-sampled by luminance × sin θ.

use std::path::Path;
use std::sync::Arc;

use anyhow::{bail, Context, Result};
use glam::{Mat3, Vec2, Vec3};

use crate::distribution::Distribution2D;
use crate::luminance;
use nprt_io::read_linear_rgb;

use std::f32::consts::PI;

#[derive(Debug)]
struct EnvData {
    name: String,
    width: usize,
    height: usize,
    /// Row-major linear RGB radiance, top row = +Y pole.
    texels: Vec<Vec3>,
    /// Over the `width × (height-1)` bilinear patches between texel centres.
    dist: Distribution2D,
    /// Negative texel channels that were clamped to zero on load.
    clamped: usize,
}

/// An environment map placed in the world. Cloning and rotating are cheap: texels and the
/// sampling distribution are shared.
#[derive(Clone, Debug)]
pub struct EnvMap {
    data: Arc<EnvData>,
    to_world: Mat3,
    to_local: Mat3,
}

/// Local direction of lat-long coordinates, the inverse of [`direction_to_uv`].
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let (sin_t, cos_t) = (uv.y * PI).sin_cos();
    let (sin_p, cos_p) = (uv.x * 2.0 * PI).sin_cos();
    Vec3::new(sin_p * sin_t, cos_t, -cos_p * sin_t)
}

/// DESIGN.md's mapping (Mitsuba 3's): u = atan2(x, −z)/2π wrapped to [0,1), v = acos(y)/π.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let u = d.x.atan2(-d.z) / (2.0 * PI);
    Vec2::new(u - u.floor(), d.y.clamp(-1.0, 1.0).acos() / PI)
}

/// The largest texel channel a map may hold: the sun's disc in real captures is below 1e9,
/// and sums over a map of brighter texels overflow f32 (a Radiance HDR file's top exponent,
/// 1.7e38, rendered all infinite).
pub const MAX_RADIANCE: f32 = 1e12;

impl EnvMap {
    /// Bytes a map holds per texel once built: its texels (12), its sampling distribution
    /// (a density and a cumulative sum, 8) and the caller's copy on the way in (12).
    const BYTES_PER_TEXEL: u128 = 32;

    /// Refuses a `width` × `height` map (`name`) the machine's memory cannot hold once built,
    /// before anything is allocated for it (a numpy array from Python, a decoded file).
    pub fn check_size(width: usize, height: usize, name: &str) -> Result<()> {
        nprt_io::ensure_memory(
            width as u128 * height as u128 * Self::BYTES_PER_TEXEL,
            &format!("{name}: an environment map of {width}×{height} texels"),
        )
    }

    /// Builds a map from row-major texels; `width` must be twice `height`. Negative channels
    /// (small ones occur in real captures) are clamped to zero and counted; non-finite ones
    /// are an error.
    pub fn from_texels(
        name: &str,
        width: usize,
        height: usize,
        mut texels: Vec<Vec3>,
    ) -> Result<Self> {
        if width != 2 * height || height < 2 {
            bail!("{name}: a lat-long environment map must be 2:1 and at least 4×2 texels, got {width}×{height}");
        }
        if texels.len() != width * height {
            bail!(
                "{name}: expected {} texels, got {}",
                width * height,
                texels.len()
            );
        }
        if let Some(i) = texels
            .iter()
            .position(|t| !t.is_finite() || t.max_element() > MAX_RADIANCE)
        {
            bail!(
                "{name}: texel ({}, {}) is {}, not a finite radiance of at most {MAX_RADIANCE:e} (a corrupt file, or a scale far too large)",
                i % width,
                i / width,
                texels[i]
            );
        }
        let clamped = texels
            .iter()
            .map(|t| t.cmplt(Vec3::ZERO).bitmask().count_ones() as usize)
            .sum();
        for t in &mut texels {
            *t = t.max(Vec3::ZERO);
        }
        let patches_y = height - 1;
        let mut func = Vec::with_capacity(width * patches_y);
        for y in 0..patches_y {
            let sin_t = (((y as f32 + 0.5) / patches_y as f32) * PI).sin();
            for x in 0..width {
                let x1 = (x + 1) % width;
                let corners = [
                    texels[y * width + x],
                    texels[y * width + x1],
                    texels[(y + 1) * width + x],
                    texels[(y + 1) * width + x1],
                ];
                // The brightest corner bounds the bilinear patch, so no lit direction gets pdf 0.
                let lmax = corners.iter().map(|&c| luminance(c)).fold(0.0, f32::max);
                func.push(lmax * sin_t);
            }
        }
        let dist = Distribution2D::new(&func, width);
        let data = EnvData {
            name: name.to_string(),
            width,
            height,
            texels,
            dist,
            clamped,
        };
        Ok(Self {
            data: Arc::new(data),
            to_world: Mat3::IDENTITY,
            to_local: Mat3::IDENTITY,
        })
    }

    /// A uniform map: a white furnace when `radiance` is 1.
    pub fn constant(radiance: Vec3) -> Result<Self> {
        Self::from_texels("constant", 8, 4, vec![radiance; 32])
    }

    /// Reads a lat-long map (OpenEXR, Radiance HDR, or an 8-bit image taken as sRGB), scaled
    /// by `scale`.
    pub fn load(path: &Path, scale: f32) -> Result<Self> {
        let name = path.display().to_string();
        // The reader's message names the file already.
        let img = read_linear_rgb(path, false).context("environment map")?;
        let texels = img.texels.into_iter().map(|t| t * scale).collect();
        Self::from_texels(&name, img.width, img.height, texels)
            .with_context(|| format!("environment map '{name}'"))
    }

    pub fn name(&self) -> &str {
        &self.data.name
    }
    pub fn width(&self) -> usize {
        self.data.width
    }
    pub fn height(&self) -> usize {
        self.data.height
    }
    /// Whether `other` shares this map's texels (the same map, however placed).
    pub fn same_texels(&self, other: &EnvMap) -> bool {
        Arc::ptr_eq(&self.data, &other.data)
    }
    /// Row-major texels in the map's own frame.
    pub fn texels(&self) -> &[Vec3] {
        &self.data.texels
    }
    /// How many negative texel channels were clamped to zero on load.
    pub fn clamped_negative(&self) -> usize {
        self.data.clamped
    }

    /// The warnings owed to the user about a loaded map: texels clamped on load (real
    /// captures have some), or no light at all (every view under it renders black).
    pub fn warnings(&self) -> Vec<String> {
        let mut warnings = vec![];
        if self.data.clamped > 0 {
            warnings.push(format!(
                "environment map '{}': {} negative texel channels clamped to 0",
                self.name(),
                self.data.clamped
            ));
        }
        if self.data.texels.iter().all(|t| *t == Vec3::ZERO) {
            warnings.push(format!(
                "environment map '{}' is black everywhere: it lights nothing, and images under it are black",
                self.name()
            ));
        }
        warnings
    }
    /// The distribution [`Self::sample`] draws lat-long patches from (one per texel column and
    /// pair of rows, offset half a texel in u).
    pub fn distribution(&self) -> &Distribution2D {
        &self.data.dist
    }

    pub fn to_world(&self) -> Mat3 {
        self.to_world
    }

    /// The same map placed with `to_world` (a rotation; Mitsuba's emitter `to_world`).
    pub fn with_to_world(&self, to_world: Mat3) -> Self {
        Self {
            data: self.data.clone(),
            to_world,
            to_local: to_world.inverse(),
        }
    }

    /// The map with every texel multiplied by `gain` (an exposure and white-balance change),
    /// in the same placement.
    pub fn scaled(&self, gain: Vec3) -> Result<Self> {
        if gain == Vec3::ONE {
            return Ok(self.clone());
        }
        let texels = self.data.texels.iter().map(|&t| t * gain).collect();
        let (w, h) = (self.data.width, self.data.height);
        Ok(Self::from_texels(&self.data.name, w, h, texels)?.with_to_world(self.to_world))
    }

    /// This map plus each of `others`, on this map's texels and in its placement: light adds,
    /// so the sum lights a scene as the maps together do. This map's texels are kept as they
    /// are; the others are looked up (bilinearly, as they are rendered) in the direction of
    /// each texel (columns at their centres, rows from pole to pole, as [`Self::eval_uv`]
    /// places them).
    pub fn plus(&self, others: &[EnvMap]) -> Result<Self> {
        if others.is_empty() {
            return Ok(self.clone());
        }
        let (w, h) = (self.data.width, self.data.height);
        let texels = (self.data.texels.iter().enumerate())
            .map(|(i, &own)| {
                let uv = Vec2::new(
                    ((i % w) as f32 + 0.5) / w as f32,
                    (i / w) as f32 / (h - 1) as f32,
                );
                let d = self.to_world * uv_to_direction(uv);
                others.iter().fold(own, |sum, m| sum + m.eval(d))
            })
            .collect();
        let name = format!("{} + {} more", self.data.name, others.len());
        Ok(Self::from_texels(&name, w, h, texels)?.with_to_world(self.to_world))
    }

    /// The map rotated by `degrees` about +Y, on top of its current placement.
    pub fn rotated_y(&self, degrees: f32) -> Self {
        self.with_to_world(Mat3::from_rotation_y(degrees.to_radians()) * self.to_world)
    }

    fn texel(&self, x: usize, y: usize) -> Vec3 {
        self.data.texels[y * self.data.width + x % self.data.width]
    }

    /// Bilinear lookup at lat-long coordinates: columns at texel centres (periodic), rows from
    /// pole (v=0) to pole (v=1), exactly as Mitsuba 3's `envmap`.
    pub fn eval_uv(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.data.width, self.data.height);
        let mut u = uv.x - 0.5 / w as f32;
        u -= u.floor();
        let px = u * w as f32;
        let py = uv.y.clamp(0.0, 1.0) * (h - 1) as f32;
        let x0 = (px as usize).min(w - 1);
        let y0 = (py as usize).min(h - 2);
        let (fx, fy) = (px - x0 as f32, py - y0 as f32);
        let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), fx);
        let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), fx);
        top.lerp(bottom, fy)
    }

    /// Radiance arriving from world direction `d` (pointing away from the scene).
    pub fn eval(&self, d: Vec3) -> Vec3 {
        self.eval_uv(direction_to_uv(self.to_local * d))
    }

    /// Samples a world direction towards the map from three uniforms: (direction, radiance,
    /// solid-angle pdf).
    pub fn sample(&self, u: Vec3) -> (Vec3, Vec3, f32) {
        let (patch_uv, pdf_uv) = self.data.dist.sample(u);
        let mut uv = patch_uv;
        uv.x += 0.5 / self.data.width as f32;
        uv.x -= uv.x.floor();
        let sin_t = (uv.y * PI).sin();
        if pdf_uv <= 0.0 || sin_t <= 1e-6 {
            return (Vec3::Y, Vec3::ZERO, 0.0);
        }
        let d = self.to_world * uv_to_direction(uv);
        (d, self.eval_uv(uv), pdf_uv / (2.0 * PI * PI * sin_t))
    }

    /// Solid-angle density with which [`EnvMap::sample`] picks world direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        self.eval_pdf(d).1
    }

    /// [`EnvMap::eval`] and [`EnvMap::pdf`] together, sharing the coordinate conversion (the
    /// path tracer needs both for every ray that escapes).
    pub fn eval_pdf(&self, d: Vec3) -> (Vec3, f32) {
        let local = self.to_local * d;
        let uv = direction_to_uv(local);
        let radiance = self.eval_uv(uv);
        let sin_t = (local.x * local.x + local.z * local.z).sqrt();
        if sin_t <= 1e-6 {
            return (radiance, 0.0);
        }
        let mut patch = uv;
        patch.x -= 0.5 / self.data.width as f32;
        patch.x -= patch.x.floor();
        (
            radiance,
            self.data.dist.pdf(patch) / (2.0 * PI * PI * sin_t),
        )
    }

    /// Mean radiance over the sphere (solid-angle weighted).
    pub fn mean_radiance(&self) -> Vec3 {
        let (w, h) = (self.data.width, self.data.height);
        let (mut sum, mut wsum) = (Vec3::ZERO, 0.0);
        for y in 0..h {
            let s = ((y as f32 / (h - 1) as f32) * PI).sin().max(1e-4);
            for x in 0..w {
                sum += self.texel(x, y) * s;
                wsum += s;
            }
        }
        sum / wsum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient_map() -> EnvMap {
        let (w, h) = (32, 16);
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                Vec3::new(
                    x as f32 + 1.0,
                    (h - y) as f32,
                    if x == 5 && y == 4 { 500.0 } else { 0.5 },
                )
            })
            .collect();
        EnvMap::from_texels("gradient", w, h, texels).unwrap()
    }

    #[test]
    fn uv_mapping_round_trips_and_matches_design() {
        for &d in &[
            Vec3::new(0.3, 0.5, -0.8),
            Vec3::new(-0.9, -0.1, 0.2),
            Vec3::new(0.0, 0.2, 1.0),
        ] {
            let d = d.normalize();
            assert!((uv_to_direction(direction_to_uv(d)) - d).length() < 1e-5);
        }
        // -Z is the centre column, +X a quarter turn to the right, +Y the top row.
        assert!((direction_to_uv(-Vec3::Z) - Vec2::new(0.0, 0.5)).length() < 1e-6);
        assert!((direction_to_uv(Vec3::X) - Vec2::new(0.25, 0.5)).length() < 1e-6);
        assert!(direction_to_uv(Vec3::Y).y.abs() < 1e-6);
    }

    #[test]
    fn lookup_hits_texel_centres_like_mitsuba() {
        let m = gradient_map();
        // Column x sits at u = (x+0.5)/w; row y at v = y/(h-1).
        let v = m.eval_uv(Vec2::new(5.5 / 32.0, 4.0 / 15.0));
        assert!((v - Vec3::new(6.0, 12.0, 500.0)).length() < 1e-3, "{v}");
        // Wrap-around between the last and first column.
        let v = m.eval_uv(Vec2::new(0.0, 0.0));
        assert!((v.x - 16.5).abs() < 1e-3, "{v}");
    }

    #[test]
    fn scaling_multiplies_radiance_and_keeps_the_placement() {
        let m = gradient_map().rotated_y(37.0);
        let gain = Vec3::new(2.0, 0.5, 1.0);
        let s = m.scaled(gain).unwrap();
        for d in [Vec3::X, Vec3::new(0.3, 0.5, -0.8).normalize(), -Vec3::Y] {
            assert!((s.eval(d) - m.eval(d) * gain).length() < 1e-4 * m.eval(d).length());
        }
        assert_eq!(s.to_world(), m.to_world());
    }

    /// A sum keeps this map's texels and placement and adds the others where they are: twice
    /// a map is twice its radiance; a turned map adds what it holds in each direction of this
    /// one's texels.
    #[test]
    fn a_sum_of_maps_adds_their_radiance() {
        let m = gradient_map().rotated_y(20.0);
        let twice = m.plus(std::slice::from_ref(&m)).unwrap();
        let turned = gradient_map()
            .rotated_y(75.0)
            .scaled(Vec3::splat(0.5))
            .unwrap();
        let both = m.plus(&[m.clone(), turned.clone()]).unwrap();
        assert_eq!(twice.to_world(), m.to_world());
        // Not the pole rows: each is one direction, whichever column is asked for.
        for (x, y) in [(5, 4), (0, 1), (31, 14), (17, 9)] {
            let d =
                m.to_world() * uv_to_direction(Vec2::new((x as f32 + 0.5) / 32.0, y as f32 / 15.0));
            let own = m.texel(x, y);
            assert!(
                (twice.texel(x, y) - 2.0 * own).length() < 1e-3 * own.length(),
                "{x} {y}"
            );
            let want = 2.0 * own + turned.eval(d);
            assert!(
                (both.texel(x, y) - want).length() < 1e-3 * want.length(),
                "{x} {y}"
            );
        }
        assert!(m.plus(&[]).unwrap().same_texels(&m));
    }

    #[test]
    fn sampling_pdf_is_consistent_and_normalised() {
        let m = gradient_map().rotated_y(37.0);
        // pdf integrates to one over the sphere (midpoint rule in θ, φ).
        let (nt, np) = (400, 800);
        let mut total = 0.0f64;
        for j in 0..nt {
            let t = (j as f32 + 0.5) / nt as f32 * PI;
            for i in 0..np {
                let p = (i as f32 + 0.5) / np as f32 * 2.0 * PI;
                let d = Vec3::new(t.sin() * p.cos(), t.cos(), t.sin() * p.sin());
                total += (m.pdf(d) * t.sin()) as f64
                    * (PI as f64 / nt as f64)
                    * (2.0 * PI as f64 / np as f64);
            }
        }
        assert!((total - 1.0).abs() < 5e-3, "pdf integrates to {total}");
        // Samples report the pdf and radiance that pdf() and eval() give for their direction.
        for k in 0..200 {
            // Irrational steps keep samples off cell edges, where rounding may pick either cell.
            let u = Vec3::new(
                ((k as f32 + 0.5) * 0.618).fract(),
                (k as f32 * 0.377 + 0.1).fract(),
                (k as f32 * 0.123 + 0.3).fract(),
            );
            let (d, l, pdf) = m.sample(u);
            assert!(pdf > 0.0);
            assert!(
                (m.pdf(d) - pdf).abs() <= 2e-3 * pdf,
                "{} vs {}",
                m.pdf(d),
                pdf
            );
            assert!((m.eval(d) - l).length() <= 1e-3 * l.length().max(1.0));
        }
    }

    #[test]
    fn radiance_hdr_files_load_texel_for_texel() {
        let path = std::env::temp_dir().join(format!("nprt-map-{}.hdr", std::process::id()));
        let img = image::Rgb32FImage::from_fn(16, 8, |x, y| {
            image::Rgb([x as f32 * 0.5, y as f32 * 2.0, 0.25])
        });
        img.save(&path).unwrap();
        let m = EnvMap::load(&path, 2.0).unwrap();
        assert_eq!((m.width(), m.height()), (16, 8));
        // RGBE keeps 8 mantissa bits per channel.
        let t = m.texels()[3 * 16 + 5];
        assert!(
            (t - Vec3::new(5.0, 12.0, 0.5)).abs().max_element() < 0.05 * 12.0,
            "{t}"
        );
    }

    #[test]
    fn clamps_negative_texels_and_rejects_non_finite_ones() {
        let mut t = vec![Vec3::ONE; 32];
        t[3] = Vec3::new(-0.5, 1.0, -0.1);
        let m = EnvMap::from_texels("neg", 8, 4, t.clone()).unwrap();
        assert_eq!(m.clamped_negative(), 2);
        assert_eq!(m.texels()[3], Vec3::new(0.0, 1.0, 0.0));
        t[5] = Vec3::new(f32::NAN, 0.0, 0.0);
        let err = EnvMap::from_texels("nan.exr", 8, 4, t)
            .unwrap_err()
            .to_string();
        assert!(err.contains("nan.exr") && err.contains("(5, 0)"), "{err}");
        assert_eq!(m.warnings().len(), 1, "{:?}", m.warnings());
    }

    /// A Radiance HDR texel at the top exponent (1.7e38) made every sum over the map infinite.
    #[test]
    fn rejects_texels_beyond_any_real_radiance_and_warns_of_black_maps() {
        let mut t = vec![Vec3::ONE; 32];
        t[9] = Vec3::new(0.0, 1.7e38, 0.0);
        let err = EnvMap::from_texels("huge.hdr", 8, 4, t)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("huge.hdr") && err.contains("(1, 1)") && err.contains("1e12"),
            "{err}"
        );
        let bright = vec![Vec3::splat(MAX_RADIANCE); 32];
        assert!(EnvMap::from_texels("sun", 8, 4, bright)
            .unwrap()
            .warnings()
            .is_empty());
        let black = EnvMap::from_texels("black.exr", 8, 4, vec![Vec3::ZERO; 32]).unwrap();
        let warnings = black.warnings();
        assert!(
            warnings.len() == 1
                && warnings[0].contains("black.exr")
                && warnings[0].contains("black everywhere"),
            "{warnings:?}"
        );
    }

    #[test]
    fn rejects_maps_that_are_not_two_to_one() {
        let err = EnvMap::from_texels("odd.exr", 30, 16, vec![Vec3::ONE; 480]).unwrap_err();
        assert!(err.to_string().contains("2:1"), "{err}");
    }
}
