//! The Neural Radiance Cache's network (Müller, Rousselle, Novák, Keller 2021), the baseline
//! the paper's Table 6 compares with: the radiance leaving a surface point in a direction, from
//! the point's position (nprt's multiresolution hash grid), the direction and the normal
//! (spherical harmonics to band 3, 16 values each), roughness (1 − e^−α) and albedos, through
//! a ReLU MLP 64 wide with 5 hidden layers; the radiance is its output times the point's albedo
//! kd + ks, so the network learns the smoother rest. It trains online while it renders
//! (nprt-eval's NRC), on the CPU engine (`cpu::radiance_cache`) or the GPU kernels
//! (`gpu::radiance_cache`), through `training::cache_trainer`.

use glam::Vec3;

use crate::encoding::hash_grid::{self, HashGrid};
use crate::init::Init;
use crate::network::activation::Activation;
use crate::network::mlp::Mlp;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// Spherical-harmonics bands of the direction's and the normal's encodings (16 values each).
pub const SH_BANDS: usize = 4;
/// Inputs of the MLP: the grid's features, two SH encodings, roughness, kd and ks.
pub const INPUTS: usize = hash_grid::OUTPUTS + 2 * SH_BANDS * SH_BANDS + 1 + 6;
/// Width and hidden layers of the MLP (Müller et al.'s).
pub const WIDTH: usize = 64;
pub const HIDDEN: usize = 5;

/// Adam's β1 and β2 for the cache. β2 is Müller et al.'s 0.99 (not the usual 0.999), and β1
/// 0.5 (theirs is 0.9): their targets move when the light changes, and with β1 0.9 the
/// momentum carried a cache past a tripled sky to twice its value, where relative L2's
/// gradients are weak, and it swung for a dozen frames (tests/nrc.rs in nprt-eval); with 0.5 it
/// settles within two frames.
pub const ADAM_BETAS: [f32; 2] = [0.5, 0.99];

/// Where and in which direction the cache is read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CacheQuery {
    /// Position normalised to [−1, 1]³ by the scene's bounds.
    pub position: [f32; 3],
    /// Unit direction the radiance leaves in (towards the previous path vertex).
    pub dir: Vec3,
    /// Unit shading normal.
    pub normal: Vec3,
    /// GGX α.
    pub roughness: f32,
    pub kd: Vec3,
    pub ks: Vec3,
}

impl CacheQuery {
    /// What the network's output is multiplied by: the point's albedo, kd + ks (at least a
    /// little, so that a black surface's cache still learns).
    pub fn albedo(&self) -> Vec3 {
        (self.kd + self.ks).max(Vec3::splat(1e-3))
    }
}

/// The cache's weights, or (same shapes) their gradient.
#[derive(Clone, Debug, PartialEq)]
pub struct RadianceCache {
    pub grid: HashGrid,
    pub mlp: Mlp,
}

impl RadianceCache {
    pub fn new(init: &mut Init) -> Self {
        let mut widths = vec![INPUTS];
        widths.extend([WIDTH; HIDDEN]);
        widths.push(3);
        RadianceCache {
            grid: HashGrid::new(init),
            mlp: Mlp::new(init, &widths, Activation::Relu),
        }
    }
}

impl Parameters for RadianceCache {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        self.grid.visit(&child(prefix, "grid"), f);
        self.mlp.visit(&child(prefix, "mlp"), f);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        self.grid.visit_mut(&child(prefix, "grid"), f);
        self.mlp.visit_mut(&child(prefix, "mlp"), f);
    }
}

/// A radiance cache trained online on an engine: its weights and Adam's state there.
pub trait CacheSteps: Send {
    /// The weights as they stand.
    fn cache(&self) -> RadianceCache;
    /// The radiance the cache holds for each query.
    fn read(&mut self, queries: &[CacheQuery]) -> Vec<Vec3>;
    /// One Adam step on the pairs at learning rate `lr`; returns their loss before it.
    fn step(&mut self, queries: &[CacheQuery], targets: &[Vec3], lr: f64) -> f64;
}
