//! The dataset's manifest (docs/dataset.md): the settings, maps, volume and views a dataset
//! was made from, checked once where it is read.

use std::path::Path;

use anyhow::{bail, Context, Result};
use glam::{Mat4, Vec3};
use nprt_scene::{Camera, CameraVolume, EnvMap, FovAxis};
use nprt_trace::TraceDevice;
use serde::{Deserialize, Serialize};

use super::transfer::TransferBasis;
use super::view_parts::ViewParts;

pub const FORMAT_VERSION: u32 = 1;
pub const MANIFEST: &str = "manifest.json";

/// Everything that determines a dataset's content; two runs agree on it or must not share a folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub format_version: u32,
    pub scene: String,
    /// BLAKE3 of the loaded geometry and the scene source (see [`super::scene_hash`]).
    pub scene_hash: String,
    pub envmaps: Vec<MapRecord>,
    pub train_maps: Vec<usize>,
    pub test_maps: Vec<usize>,
    pub train_views: u64,
    pub test_views: u64,
    pub train_resolution: [u32; 2],
    pub test_resolution: [u32; 2],
    /// Samples per pixel of the training views.
    pub spp: u32,
    /// Samples per pixel of the test views (the references of evaluation), rendered as two
    /// independent halves whose first is kept to measure the reference's own noise. Absent in
    /// datasets made before it existed: their test views are at `spp`, in one piece.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub test_spp: Option<u32>,
    pub max_depth: Option<u32>,
    pub rr_depth: u32,
    pub seed: u64,
    /// Random exposure and white-balance changes of the training views' maps.
    #[serde(default, skip_serializing_if = "Jitter::is_none")]
    pub jitter: Jitter,
    /// The most maps a training view's lighting mixes (`nprt generate --mix-maps`; absent: 1,
    /// one map a view).
    #[serde(default = "one_map", skip_serializing_if = "is_one_map")]
    pub mix_maps: u32,
    pub camera_volume: VolumeRecord,
    /// The basis the training views' transfer vectors are recorded on (`nprt generate
    /// --transfer`); absent: none recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<TransferBasis>,
    /// Which tracer began the dataset (informative: the two draw different random numbers but
    /// agree within noise, so a dataset is resumed, or trained on, with either). Absent in
    /// datasets made before the GPU tracer: the CPU's.
    #[serde(default)]
    pub tracer: TraceDevice,
}

/// How far a training view's map may be brightened, darkened and tinted, in stops: its gain
/// is 2^e · (2^r, 1, 2^b) normalised to unit luminance, with e uniform in ±`exposure` and r, b
/// in ±`tint`. Test views are never jittered.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Jitter {
    pub exposure: f32,
    pub tint: f32,
}

impl Jitter {
    pub fn is_none(&self) -> bool {
        self.exposure == 0.0 && self.tint == 0.0
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapRecord {
    /// File path or built-in spec, as given.
    pub spec: String,
    /// BLAKE3 of the file's bytes (of the spec for built-in maps).
    pub hash: String,
    pub width: usize,
    pub height: usize,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VolumeRecord {
    pub min: [f32; 3],
    pub max: [f32; 3],
    pub look: [f32; 3],
    pub spread_deg: f32,
    pub fov_deg: f32,
}

impl VolumeRecord {
    /// The camera volume this record states.
    pub fn volume(&self) -> CameraVolume {
        CameraVolume {
            min: self.min.into(),
            max: self.max.into(),
            look: self.look.into(),
            spread_deg: self.spread_deg,
            fov_deg: self.fov_deg,
        }
    }
}

impl From<&CameraVolume> for VolumeRecord {
    /// The volume a dataset's cameras are placed in, for its manifest.
    fn from(v: &CameraVolume) -> Self {
        VolumeRecord {
            min: v.min.into(),
            max: v.max.into(),
            look: v.look.into(),
            spread_deg: v.spread_deg,
            fov_deg: v.fov_deg,
        }
    }
}

impl From<&VolumeRecord> for CameraVolume {
    /// The volume a dataset's cameras were placed in, as recorded.
    fn from(v: &VolumeRecord) -> Self {
        CameraVolume {
            min: v.min.into(),
            max: v.max.into(),
            // A zero direction stays zero, for `CameraVolume::problem` to refuse.
            look: CameraVolume::direction(Vec3::from(v.look)),
            spread_deg: v.spread_deg,
            fov_deg: v.fov_deg,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewRecord {
    pub index: u64,
    /// "train" or "test".
    pub split: String,
    /// Relative to the dataset folder.
    pub file: String,
    /// Camera-to-world, column-major, Mitsuba's camera convention (+Z forward, +Y up, +X left).
    pub camera_to_world: [f32; 16],
    /// Horizontal field of view, degrees.
    pub fov_x_deg: f32,
    pub width: u32,
    pub height: u32,
    /// Index into `settings.envmaps`.
    pub map: usize,
    /// Rotation of the map about +Y, degrees.
    pub rotation_deg: f32,
    /// RGB factor of the map's radiance (exposure and white balance; see [`Jitter`]).
    #[serde(default = "unit_gain", skip_serializing_if = "is_unit_gain")]
    pub gain: [f32; 3],
    /// Seed of the view's per-pixel random streams.
    pub seed: u64,
    /// Further maps added to a training view's lighting (`nprt generate --mix-maps`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mix: Vec<MixTerm>,
}

/// A map added to a training view's lighting: light adds, so the view is lit by its own map
/// plus each of these, rotated about +Y and scaled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MixTerm {
    /// Index into `settings.envmaps`, one of the training maps.
    pub map: usize,
    pub rotation_deg: f32,
    /// What its radiance is multiplied by, in [1/64, 1].
    pub gain: f32,
}

fn one_map() -> u32 {
    1
}

fn is_one_map(n: &u32) -> bool {
    *n <= 1
}

fn unit_gain() -> [f32; 3] {
    [1.0; 3]
}

fn is_unit_gain(g: &[f32; 3]) -> bool {
    *g == unit_gain()
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub settings: Settings,
    /// Scene bounds (min, max) for normalising positions to [-1, 1].
    pub bounds: [[f32; 3]; 2],
    pub views: Vec<ViewRecord>,
}

impl Manifest {
    /// Parses and [checks](Manifest::check) a manifest's JSON.
    pub fn from_json(bytes: &[u8]) -> Result<Manifest> {
        let manifest: Manifest = serde_json::from_slice(bytes).context("not a valid manifest")?;
        manifest.check()?;
        Ok(manifest)
    }

    /// Refuses a manifest that a hand edit or another tool made inconsistent, so that every
    /// later use (map indices, image sizes, cameras, file names) can trust it.
    pub fn check(&self) -> Result<()> {
        let s = &self.settings;
        if s.format_version != FORMAT_VERSION {
            bail!(
                "format_version is {}, this nprt reads {FORMAT_VERSION}",
                s.format_version
            );
        }
        if s.spp == 0 {
            bail!("spp is 0: training views need at least one sample per pixel");
        }
        if let Some(n) = s.test_spp {
            if n < 2 || n % 2 != 0 {
                bail!("test_spp is {n}: it must be even and at least 2 (test views are rendered as two independent halves)");
            }
        }
        if let Some(p) = CameraVolume::from(&s.camera_volume).problem() {
            bail!("camera_volume: {p}");
        }
        let maps = s.envmaps.len();
        if let Some(&i) = s
            .train_maps
            .iter()
            .chain(&s.test_maps)
            .find(|&&i| i >= maps)
        {
            bail!("map index {i} is out of range: settings.envmaps lists {maps} maps");
        }
        if s.train_maps.is_empty() || s.test_maps.is_empty() {
            bail!("settings.train_maps and settings.test_maps must each name at least one map");
        }
        if let Some(i) = s.train_maps.iter().find(|i| s.test_maps.contains(i)) {
            bail!("map {i} is both a training and a test map: test lightings must be unseen in training");
        }
        check_bounds(&self.bounds)?;
        for v in &self.views {
            self.check_view(v)?;
        }
        self.check_view_list()
    }

    /// A view's mixed maps: training views only, at most `mix_maps` maps in all, each a
    /// training map with a finite rotation and a gain in [1/64, 1].
    fn check_mix(&self, v: &ViewRecord, what: &str) -> Result<()> {
        let s = &self.settings;
        if v.mix.is_empty() {
            return Ok(());
        }
        if v.split != "train" || v.mix.len() + 1 > s.mix_maps.max(1) as usize {
            bail!(
                "{what}: mixes {} maps, but only training views mix, at most {} (mix_maps)",
                v.mix.len() + 1,
                s.mix_maps.max(1)
            );
        }
        for t in &v.mix {
            if !s.train_maps.contains(&t.map) {
                bail!("{what}: mixed map {} is not a training map", t.map);
            }
            if !t.rotation_deg.is_finite() || !(1.0 / 64.0..=1.0).contains(&t.gain) {
                bail!(
                    "{what}: mixed map {} has rotation {} and gain {}: a finite rotation and a \
                     gain in [1/64, 1] are needed",
                    t.map,
                    t.rotation_deg,
                    t.gain
                );
            }
        }
        Ok(())
    }

    /// One view against the settings: its split's maps and resolution, a plausible size and
    /// field of view, a rigid camera, a gain in range (none for a test view) and a file inside
    /// the dataset folder.
    fn check_view(&self, v: &ViewRecord) -> Result<()> {
        let s = &self.settings;
        let what = format!("view {} ('{}')", v.index, v.file);
        let allowed = match v.split.as_str() {
            "train" => &s.train_maps,
            "test" => &s.test_maps,
            other => bail!("{what}: split '{other}' is neither 'train' nor 'test'"),
        };
        if !allowed.contains(&v.map) {
            bail!(
                "{what}: map {} is not one of its split's maps {allowed:?}",
                v.map
            );
        }
        if v.width == 0 || v.height == 0 || v.width as u64 * v.height as u64 > 1 << 28 {
            bail!(
                "{what}: size {}×{} is empty or implausibly large",
                v.width,
                v.height
            );
        }
        if !(v.fov_x_deg > 0.0 && v.fov_x_deg < 180.0) {
            bail!("{what}: fov_x_deg {} is not in (0, 180)", v.fov_x_deg);
        }
        if !v.camera_to_world.iter().all(|x| x.is_finite()) || !v.rotation_deg.is_finite() {
            bail!("{what}: camera_to_world or rotation_deg holds a non-finite number");
        }
        if !is_rigid(&Mat4::from_cols_array(&v.camera_to_world)) {
            bail!("{what}: camera_to_world is not a rotation and translation (orthonormal axes, last row 0 0 0 1)");
        }
        let resolution = if v.split == "train" {
            s.train_resolution
        } else {
            s.test_resolution
        };
        if [v.width, v.height] != resolution {
            bail!(
                "{what}: size {}×{} is not its split's resolution {}×{}",
                v.width,
                v.height,
                resolution[0],
                resolution[1]
            );
        }
        if !v.gain.iter().all(|g| (1.0 / 64.0..=64.0).contains(g)) {
            bail!("{what}: gain {:?} is not within [1/64, 64]", v.gain);
        }
        self.check_mix(v, &what)?;
        if v.split == "test" && !is_unit_gain(&v.gain) {
            bail!(
                "{what}: a test view's map is never jittered, but its gain is {:?}",
                v.gain
            );
        }
        // Plain names only: '.', '..' or a root would let two spellings name one file (a view
        // trained on twice), or name one outside the folder.
        let file = Path::new(&v.file);
        if !file
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
        {
            bail!(
                "{what}: file must be a plain path inside the dataset folder (no '.', '..' or leading '/')"
            );
        }
        Ok(())
    }
}

impl Manifest {
    /// The view list against the settings: one view per index 0..n in order, unique files,
    /// and as many views of each split as the settings say.
    fn check_view_list(&self) -> Result<()> {
        let s = &self.settings;
        if self.views.is_empty() {
            bail!("the manifest lists no views");
        }
        let mut files = std::collections::HashSet::new();
        for (i, v) in self.views.iter().enumerate() {
            if v.index != i as u64 {
                bail!(
                    "view {i} of the list has index {} (indices run 0, 1, … in order)",
                    v.index
                );
            }
            // Compared as paths: "views//a.exr" names "views/a.exr".
            if !files.insert(
                Path::new(&v.file)
                    .components()
                    .collect::<std::path::PathBuf>(),
            ) {
                bail!("file '{}' is named by more than one view", v.file);
            }
        }
        let count = |split: &str| self.views.iter().filter(|v| v.split == split).count() as u64;
        for (split, planned) in [("train", s.train_views), ("test", s.test_views)] {
            if count(split) != planned {
                bail!(
                    "the settings plan {planned} {split} views, but the list holds {}",
                    count(split)
                );
            }
        }
        Ok(())
    }
}

/// Whether `m` only rotates and translates (what a camera's placement does; an all-zero
/// matrix, say, gave NaN rays and metrics).
fn is_rigid(m: &Mat4) -> bool {
    let [x, y, z] = [
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    ];
    let unit = |a: Vec3| (a.length() - 1.0).abs() < 1e-3;
    let orthogonal = |a: Vec3, b: Vec3| a.dot(b).abs() < 1e-3;
    [x, y, z].into_iter().all(unit)
        && orthogonal(x, y)
        && orthogonal(y, z)
        && orthogonal(x, z)
        && m.row(3) == glam::Vec4::W
}

impl Settings {
    /// The fields in which `self` and `other` differ, each with both values: what a refusal to
    /// mix two datasets names.
    pub fn differences(&self, other: &Settings) -> Vec<String> {
        let (serde_json::Value::Object(a), serde_json::Value::Object(b)) = (
            serde_json::to_value(self).unwrap_or_default(),
            serde_json::to_value(other).unwrap_or_default(),
        ) else {
            return vec![];
        };
        let null = serde_json::Value::Null;
        let mut keys: Vec<&String> = a.keys().chain(b.keys()).collect();
        keys.sort();
        keys.dedup();
        keys.into_iter()
            .filter_map(|k| {
                let (x, y) = (a.get(k).unwrap_or(&null), b.get(k).unwrap_or(&null));
                (x != y).then(|| format!("{k} ({} here, {} asked)", brief(x), brief(y)))
            })
            .collect()
    }

    /// Whether `view`'s file holds the first half of its samples apart (see [`Settings::test_spp`]).
    pub fn in_halves(&self, view: &ViewRecord) -> bool {
        view.split == "test" && self.test_spp.is_some()
    }

    /// What `view`'s file holds beside its frame: the first half's radiance (a test view in
    /// halves), transfer vectors (a training view of a dataset with `--transfer`).
    pub fn parts(&self, view: &ViewRecord) -> ViewParts {
        ViewParts {
            halves: self.in_halves(view),
            transfer: self.transfer.filter(|_| view.split == "train"),
        }
    }

    /// Samples per pixel of `view`.
    pub fn spp_of(&self, view: &ViewRecord) -> u32 {
        match (view.split.as_str(), self.test_spp) {
            ("test", Some(n)) => n,
            _ => self.spp,
        }
    }
}

impl ViewRecord {
    /// The view's lighting: its map, scaled by its gain and rotated by its rotation, plus its
    /// mixed maps.
    pub fn lighting(&self, maps: &[EnvMap]) -> Result<EnvMap> {
        let map = |m: usize| {
            maps.get(m)
                .with_context(|| format!("view '{}' names map {m} of {}", self.file, maps.len()))
        };
        let own = self.own_light(map(self.map)?)?;
        let mixed = (self.mix.iter())
            .map(|t| {
                Ok(map(t.map)?
                    .scaled(Vec3::splat(t.gain))?
                    .rotated_y(t.rotation_deg))
            })
            .collect::<Result<Vec<EnvMap>>>()?;
        own.plus(&mixed)
    }

    /// The view's lighting made from its own map `map` (the manifest's map `self.map`); a view
    /// that mixes maps needs them all ([`Self::lighting`]).
    pub fn light(&self, map: &EnvMap) -> Result<EnvMap> {
        if !self.mix.is_empty() {
            bail!(
                "view '{}' mixes {} maps into its lighting: all of them are needed",
                self.file,
                self.mix.len() + 1
            );
        }
        self.own_light(map)
    }

    fn own_light(&self, map: &EnvMap) -> Result<EnvMap> {
        Ok(map
            .scaled(Vec3::from_array(self.gain))?
            .rotated_y(self.rotation_deg))
    }

    /// Every map the view's lighting reads: its own, then its mixed ones.
    pub fn maps(&self) -> impl Iterator<Item = usize> + '_ {
        std::iter::once(self.map).chain(self.mix.iter().map(|t| t.map))
    }

    pub fn camera(&self) -> Camera {
        Camera {
            to_world: Mat4::from_cols_array(&self.camera_to_world),
            fov_deg: self.fov_x_deg,
            fov_axis: FovAxis::X,
            width: self.width,
            height: self.height,
        }
    }
}

pub fn load_manifest(dir: &Path) -> Result<Manifest> {
    Ok(load_manifest_hashed(dir)?.0)
}

/// The manifest of the dataset in `dir` and the dataset's hash (of the manifest's bytes, which
/// fix every view's camera, map, rotation and seed); models record it to refuse other data.
pub fn load_manifest_hashed(dir: &Path) -> Result<(Manifest, String)> {
    let path = dir.join(MANIFEST);
    let bytes = nprt_io::read_input(&path)?;
    let manifest = Manifest::from_json(&bytes)
        .with_context(|| format!("'{}' is not a usable nprt dataset manifest", path.display()))?;
    Ok((manifest, blake3::hash(&bytes).to_hex().to_string()))
}

/// Scene bounds positions can be normalised with: finite, min ≤ max on every axis, spanning at
/// least two (a flat scene spans two; inverted or empty bounds would map every position
/// elsewhere, silently). What a dataset's manifest and a model's config must hold.
pub fn check_bounds(bounds: &[[f32; 3]; 2]) -> Result<()> {
    let [lo, hi] = bounds;
    if !bounds.iter().flatten().all(|v| v.is_finite())
        || (0..3).any(|k| lo[k] > hi[k])
        || (0..3).filter(|&k| lo[k] < hi[k]).count() < 2
    {
        bail!("bounds {bounds:?} are not a finite box (min ≤ max) spanning at least two axes");
    }
    Ok(())
}

/// A setting's value short enough for a message: a list of maps (thousands of characters of
/// names and hashes) by its length, anything else long cut.
fn brief(v: &serde_json::Value) -> String {
    let text = v.to_string();
    match v {
        _ if text.chars().count() <= 80 => text,
        serde_json::Value::Array(items) => format!("{} entries", items.len()),
        _ => format!("{}…", text.chars().take(77).collect::<String>()),
    }
}
