//! A multiresolution hash grid on the scene's box (Müller et al., Instant Neural Graphics
//! Primitives, 2022): at each of [`LEVELS`] grid resolutions, the position's cell has eight
//! vertices, each holding [`LEVEL_FEATURES`] learned values in that level's table (directly
//! indexed while the level's vertices fit, hashed beyond); the encoding is their trilinear
//! interpolation, level after level. Gradients reach only the eight rows per level a position
//! touches.
//!
//! The vertex lookup ([`corners`]) and the interpolation ([`encode`]) and its adjoint
//! ([`scatter`]) are the CPU engine's; the GPU kernels restate them and are tested against them.

use std::sync::LazyLock;

use crate::encoding::features::feature;
use crate::init::Init;
use crate::parameters::{child, Parameters, Visit, VisitMut};

/// Grid resolutions, from [`MIN_RES`] to [`MAX_RES`] cells along each side of the scene's box
/// in a geometric progression.
pub const LEVELS: usize = 8;
/// Values per vertex.
pub const LEVEL_FEATURES: usize = 2;
/// Rows of each level's table: 0.5 MB of f32 per track in all. Levels up to 19³ cells are
/// indexed directly, finer ones hashed into this many rows.
pub const TABLE_SIZE: usize = 1 << 13;
/// Inputs the encoding adds.
pub const OUTPUTS: usize = LEVELS * LEVEL_FEATURES;
/// The coarsest and finest resolutions. Measured on the demo's data (docs/model.md): a grid
/// down to 1/512 of the box memorised its sparse, noisy training pixels (training loss far
/// down, validation loss up); down to 1/64 (9 cm in the built-in room) it did not.
const MIN_RES: f32 = 4.0;
const MAX_RES: f32 = 64.0;
const CORNERS: usize = 8;
/// Instant-NGP's initialisation: values near zero, so the untrained grid adds next to nothing.
const INIT_BOUND: f32 = 1e-4;

/// The table rows a position reads, level after level, and their trilinear weights.
pub struct Corners {
    pub row: [u32; LEVELS * CORNERS],
    pub weight: [f32; LEVELS * CORNERS],
}

/// Cells along each side at each level, made once: every pixel of every step looks them up.
static RESOLUTIONS: LazyLock<[u32; LEVELS]> = LazyLock::new(|| {
    let growth = (MAX_RES / MIN_RES).powf(1.0 / (LEVELS - 1) as f32);
    std::array::from_fn(|level| (MIN_RES * growth.powi(level as i32)).floor() as u32)
});

fn resolution(level: usize) -> u32 {
    RESOLUTIONS[level]
}

/// Cells along each side at every level: what a GPU kernel needs to find the same vertices.
pub fn resolutions() -> [u32; LEVELS] {
    *RESOLUTIONS
}

/// The vertices around `position` (normalised to [−1, 1], clamped to the box) at every level.
pub fn corners(position: [f32; 3]) -> Corners {
    let mut c = Corners {
        row: [0; LEVELS * CORNERS],
        weight: [0.0; LEVELS * CORNERS],
    };
    for level in 0..LEVELS {
        let res = resolution(level);
        let side = res + 1;
        let dense = (side as usize).pow(3) <= TABLE_SIZE;
        let mut cell = [0u32; 3];
        let mut t = [0.0f32; 3];
        for a in 0..3 {
            let p = ((position[a] + 1.0) * 0.5).clamp(0.0, 1.0) * res as f32;
            cell[a] = (p.floor() as u32).min(res - 1);
            t[a] = p - cell[a] as f32;
        }
        for k in 0..CORNERS {
            let v: [u32; 3] = std::array::from_fn(|a| cell[a] + ((k >> a) & 1) as u32);
            let slot = if dense {
                v[0] + side * (v[1] + side * v[2])
            } else {
                // The spatial hash of Teschner et al., as Instant-NGP uses it.
                (v[0] ^ v[1].wrapping_mul(2_654_435_761) ^ v[2].wrapping_mul(805_459_861))
                    % TABLE_SIZE as u32
            };
            let weight: f32 = (0..3)
                .map(|a| if (k >> a) & 1 == 1 { t[a] } else { 1.0 - t[a] })
                .product();
            c.row[level * CORNERS + k] = (level * TABLE_SIZE) as u32 + slot;
            c.weight[level * CORNERS + k] = weight;
        }
    }
    c
}

/// The position inputs of a row of pixel features.
pub fn position(features: &[f32]) -> [f32; 3] {
    std::array::from_fn(|a| features[feature::POSITION.start + a])
}

/// The encoding ([`OUTPUTS`] values into `out`) at `c` of a table held on the host
/// (`LEVELS · TABLE_SIZE × LEVEL_FEATURES`, row-major).
pub fn encode(table: &[f32], c: &Corners, out: &mut [f32]) {
    out.fill(0.0);
    for (k, (&row, &w)) in c.row.iter().zip(&c.weight).enumerate() {
        let level = k / CORNERS;
        let values = &table[row as usize * LEVEL_FEATURES..][..LEVEL_FEATURES];
        let o = &mut out[level * LEVEL_FEATURES..][..LEVEL_FEATURES];
        o.iter_mut().zip(values).for_each(|(o, v)| *o += w * v);
    }
}

/// Adds to the table gradient `grad` what the gradient `d_out` at the encoding at `c` sends
/// back: the adjoint of [`encode`].
pub fn scatter(grad: &mut [f32], c: &Corners, d_out: &[f32]) {
    for (k, (&row, &w)) in c.row.iter().zip(&c.weight).enumerate() {
        let level = k / CORNERS;
        let g = &mut grad[row as usize * LEVEL_FEATURES..][..LEVEL_FEATURES];
        let d = &d_out[level * LEVEL_FEATURES..][..LEVEL_FEATURES];
        g.iter_mut().zip(d).for_each(|(g, d)| *g += w * d);
    }
}

/// The learned tables of every level, `LEVELS · TABLE_SIZE × LEVEL_FEATURES`, or (same shape)
/// their gradient.
#[derive(Clone, Debug, PartialEq)]
pub struct HashGrid {
    pub table: Vec<f32>,
}

impl HashGrid {
    pub fn new(init: &mut Init) -> Self {
        HashGrid {
            table: init.uniform(LEVELS * TABLE_SIZE * LEVEL_FEATURES, INIT_BOUND),
        }
    }
}

impl Parameters for HashGrid {
    fn visit(&self, prefix: &str, f: &mut Visit) {
        let shape = [LEVELS * TABLE_SIZE, LEVEL_FEATURES];
        f(&child(prefix, "table"), &shape, &self.table);
    }

    fn visit_mut(&mut self, prefix: &str, f: &mut VisitMut) {
        let shape = [LEVELS * TABLE_SIZE, LEVEL_FEATURES];
        f(&child(prefix, "table"), &shape, &mut self.table);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    fn random_positions(seed: u64, n: usize) -> Vec<[f32; 3]> {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        (0..n)
            .map(|_| std::array::from_fn(|_| rng.random::<f32>() * 2.0 - 1.0))
            .collect()
    }

    /// Trilinear interpolation reproduces a linear function exactly: with every directly
    /// indexed vertex holding an affine function of its coordinates, the coarse levels'
    /// encoding is that function of the position.
    #[test]
    fn direct_levels_interpolate_vertex_values_trilinearly() {
        let mut table = vec![0.0f32; LEVELS * TABLE_SIZE * LEVEL_FEATURES];
        let direct: Vec<usize> = (0..LEVELS)
            .filter(|&l| ((resolution(l) + 1) as usize).pow(3) <= TABLE_SIZE)
            .collect();
        assert!(direct.len() >= 2, "levels indexed directly: {direct:?}");
        let f = |u: [f32; 3]| [0.3 + u[0] - 2.0 * u[1] + 0.5 * u[2], u[2] - u[0]];
        for &l in &direct {
            let side = resolution(l) + 1;
            for slot in 0..side.pow(3) {
                let v = [slot % side, slot / side % side, slot / side / side];
                let u = v.map(|c| c as f32 / resolution(l) as f32);
                let row = l * TABLE_SIZE + slot as usize;
                table[row * LEVEL_FEATURES..][..2].copy_from_slice(&f(u));
            }
        }
        let mut out = [0.0; OUTPUTS];
        for p in random_positions(1, 200)
            .into_iter()
            .chain([[1.0; 3], [-1.0; 3]])
        {
            encode(&table, &corners(p), &mut out);
            let want = f(p.map(|x| (x + 1.0) * 0.5));
            for &l in &direct {
                for k in 0..2 {
                    let got = out[l * LEVEL_FEATURES + k];
                    assert!(
                        (got - want[k]).abs() < 1e-5,
                        "level {l} at {p:?}: {got} vs {}",
                        want[k]
                    );
                }
            }
        }
    }

    /// Each level's weights are a partition of unity over rows of that level's own table, and
    /// the finest levels are hashed, not indexed out of their table.
    #[test]
    fn each_level_reads_eight_rows_of_its_own_table_with_weights_summing_to_one() {
        assert!(((resolution(LEVELS - 1) + 1) as usize).pow(3) > TABLE_SIZE);
        assert_eq!(resolution(0), MIN_RES as u32);
        assert!((resolution(LEVELS - 1) as f32 - MAX_RES).abs() <= 1.0);
        for p in random_positions(2, 300) {
            let c = corners(p);
            for l in 0..LEVELS {
                let w: f32 = c.weight[l * CORNERS..][..CORNERS].iter().sum();
                assert!((w - 1.0).abs() < 1e-5, "level {l}: weights sum to {w}");
                for &row in &c.row[l * CORNERS..][..CORNERS] {
                    assert_eq!(row as usize / TABLE_SIZE, l);
                }
            }
        }
    }

    /// `scatter` is the adjoint of `encode`: ⟨encode(T, x), d⟩ = ⟨T, scatter(x, d)⟩.
    #[test]
    fn scatter_is_the_adjoint_of_encode() {
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let table: Vec<f32> = (0..LEVELS * TABLE_SIZE * LEVEL_FEATURES)
            .map(|_| rng.random::<f32>() - 0.5)
            .collect();
        for p in random_positions(4, 50) {
            let d: Vec<f32> = (0..OUTPUTS).map(|_| rng.random::<f32>() - 0.5).collect();
            let c = corners(p);
            let mut out = [0.0; OUTPUTS];
            encode(&table, &c, &mut out);
            let lhs: f64 = out.iter().zip(&d).map(|(a, b)| (a * b) as f64).sum();
            let mut grad = vec![0.0f32; table.len()];
            scatter(&mut grad, &c, &d);
            let rhs: f64 = grad.iter().zip(&table).map(|(a, b)| (a * b) as f64).sum();
            assert!((lhs - rhs).abs() < 1e-5, "{lhs} vs {rhs}");
        }
    }
}
