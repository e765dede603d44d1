//! What a transport track reads and how its outputs make radiance: one file per kind states its
//! inputs and its combine rule once ([`KindSpec`]), and everything else derives from that
//! table: the CPU engine's forward and backward ([`TrackKind::radiance`],
//! [`TrackKind::output_gradients`]), the tests' f64 reference, and the WGSL table
//! that the training and frame kernels and the export read ([`kind_table_wgsl`]).
//!
//! A rule is a sum of terms, each the exp of three of the shading network's outputs (its
//! outputs are log-radiance: exp keeps radiance positive over its high dynamic range) times a
//! weight, 1 or a material's albedo among the pixel inputs. The linear design's tracks keep
//! their kind's rule with each term's value the dot product of K transfer coefficients with the
//! light code instead of an exp (`cpu::transport`).

mod albedo;
mod diffuse;
mod full;
mod specular;

use std::ops::Range;

use crate::encoding::features::FEATURES;

/// What multiplies a term of a track's radiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Weight {
    One,
    /// Three pixel inputs from this one (kd or ks).
    Albedo(usize),
}

impl Weight {
    /// The weight of channel `c` for the pixel inputs `f`.
    fn of(self, f: &[f32], c: usize) -> f32 {
        match self {
            Weight::One => 1.0,
            Weight::Albedo(at) => f[at + c],
        }
    }
}

/// Every pixel input, in the order of [`feature`](crate::encoding::features::feature).
pub const ALL_INPUTS: &[Range<usize>] = {
    use crate::encoding::features::feature::*;
    &[POSITION, VIEW, MIRROR, NORMAL, KD, KS, ALPHA]
};

/// One kind of track, as its file states it.
pub struct KindSpec {
    /// Its name in the export.
    pub name: &'static str,
    /// The pixel inputs it reads, in order.
    pub inputs: &'static [Range<usize>],
    /// Its radiance: term k is `weight · exp(outputs 3k..3k+3)`.
    pub terms: &'static [Weight],
}

/// Which pixel inputs a track reads, and how its outputs weight into radiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackKind {
    /// All 19 inputs; outputs are radiance.
    Full,
    /// All 19 inputs; 6 outputs, kd·exp(first 3) + ks·exp(last 3).
    Albedo,
    /// x, n, kd; weighted by kd.
    Diffuse,
    /// x, n, ks, ωo, ωr, α; weighted by ks.
    Specular,
}

impl TrackKind {
    /// Every kind, in the order of their codes on the device.
    pub const ALL: [TrackKind; 4] = [
        TrackKind::Full,
        TrackKind::Albedo,
        TrackKind::Diffuse,
        TrackKind::Specular,
    ];

    pub fn spec(self) -> &'static KindSpec {
        match self {
            TrackKind::Full => &full::SPEC,
            TrackKind::Albedo => &albedo::SPEC,
            TrackKind::Diffuse => &diffuse::SPEC,
            TrackKind::Specular => &specular::SPEC,
        }
    }

    /// The kind's code in the kernels' parameters (its index in [`Self::ALL`]).
    pub fn code(self) -> u32 {
        Self::ALL.iter().position(|&k| k == self).expect("listed") as u32
    }

    /// The feature indices the track reads, in its input order.
    pub fn inputs(self) -> Vec<usize> {
        self.spec().inputs.iter().cloned().flatten().collect()
    }

    /// Whether the track reads every pixel input in order (no gather needed).
    pub fn reads_all(self) -> bool {
        self.spec().inputs.iter().cloned().flatten().eq(0..FEATURES)
    }

    /// The shading network's outputs: three per term.
    pub fn outputs(self) -> usize {
        3 * self.spec().terms.len()
    }

    /// Radiance (before the map's scale) of a pixel with inputs `f` from the exp of its
    /// shading outputs `e`.
    pub fn radiance(self, f: &[f32], e: &[f32]) -> [f32; 3] {
        let terms = self.spec().terms;
        std::array::from_fn(|c| {
            let term = |k: usize| terms[k].of(f, c) * e[3 * k + c];
            (1..terms.len()).fold(term(0), |sum, k| sum + term(k))
        })
    }

    /// The gradient at the terms' values `d` (3 per term) from the gradient `dr` at the
    /// radiance of a pixel with inputs `f`: each term's weight times `dr`.
    pub fn term_gradients(self, f: &[f32], dr: &[f32], d: &mut [f32]) {
        for (k, w) in self.spec().terms.iter().enumerate() {
            for c in 0..3 {
                d[3 * k + c] = dr[c] * w.of(f, c);
            }
        }
    }

    /// The gradient at the shading outputs `d` from the gradient `dr` at the radiance of a
    /// pixel with inputs `f` and output exps `e` (the terms' values).
    pub fn output_gradients(self, f: &[f32], e: &[f32], dr: &[f32], d: &mut [f32]) {
        self.term_gradients(f, dr, d);
        d.iter_mut().zip(e).for_each(|(d, e)| *d *= e);
    }
}

/// Marks a term weighted by 1 in [`kind_table_wgsl`].
const ONE_WEIGHT: u32 = u32::MAX;

/// The kinds as WGSL (`track_radiance.wgsl` reads it): per kind code, its number of terms and
/// each term's weight (the first of three pixel inputs, or `ONE_WEIGHT`).
pub fn kind_table_wgsl() -> String {
    let most = TrackKind::ALL
        .iter()
        .map(|k| k.spec().terms.len())
        .max()
        .expect("kinds");
    let kinds = TrackKind::ALL.len();
    let terms: Vec<String> = TrackKind::ALL
        .iter()
        .map(|k| format!("{}u", k.spec().terms.len()))
        .collect();
    let weights: Vec<String> = TrackKind::ALL
        .iter()
        .map(|k| {
            let w: Vec<String> = (0..most)
                .map(|t| match k.spec().terms.get(t) {
                    Some(Weight::Albedo(at)) => format!("{at}u"),
                    _ => format!("{ONE_WEIGHT}u"),
                })
                .collect();
            format!("array<u32, {most}>({})", w.join(", "))
        })
        .collect();
    format!(
        "// Generated from nprt-net's TrackKind (network/track_kind): per kind code, its terms\n\
         // and each term's weight, the first of three pixel inputs or ONE_WEIGHT for 1.\n\
         const MAX_TERMS: u32 = {most}u;\n\
         const ONE_WEIGHT: u32 = {ONE_WEIGHT}u;\n\
         var<private> KIND_TERMS: array<u32, {kinds}> = array<u32, {kinds}>({});\n\
         var<private> KIND_WEIGHTS: array<array<u32, {most}>, {kinds}> = \
         array<array<u32, {most}>, {kinds}>({});\n\n",
        terms.join(", "),
        weights.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::encoding::features::feature;

    #[test]
    fn kinds_read_the_papers_inputs_and_outputs() {
        let shape: Vec<(usize, usize)> = TrackKind::ALL
            .iter()
            .map(|k| (k.inputs().len(), k.outputs()))
            .collect();
        assert_eq!(shape, [(19, 3), (19, 6), (9, 3), (16, 3)]);
        for (i, k) in TrackKind::ALL.iter().enumerate() {
            assert_eq!(k.code(), i as u32);
        }
        assert!(TrackKind::Albedo.reads_all() && !TrackKind::Diffuse.reads_all());
    }

    /// Each kind's radiance is its rule, and the gradient at its outputs (log-radiance) is the
    /// rule's derivative, checked by central differences in f64.
    #[test]
    fn the_output_gradients_are_the_rules_derivative() {
        let mut f = [0.0f32; FEATURES];
        f[feature::KD].copy_from_slice(&[0.5, 0.25, 0.125]);
        f[feature::KS].copy_from_slice(&[0.75, 0.5, 0.0625]);
        let o: Vec<f32> = (0..6).map(|i| 0.3 * i as f32 - 0.7).collect();
        let exps = |o: &[f32]| o.iter().map(|v| v.exp()).collect::<Vec<f32>>();
        let albedo = TrackKind::Albedo.radiance(&f, &exps(&o));
        for c in 0..3 {
            let want = f[12 + c] * o[c].exp() + f[15 + c] * o[3 + c].exp();
            assert!((albedo[c] - want).abs() < 1e-6);
        }
        for kind in TrackKind::ALL {
            let n = kind.outputs();
            for c in 0..3 {
                let mut dr = [0.0; 3];
                dr[c] = 1.0;
                let mut d = vec![0.0; n];
                kind.output_gradients(&f, &exps(&o[..n]), &dr, &mut d);
                for j in 0..n {
                    let at = |h: f32| {
                        let mut shifted = o[..n].to_vec();
                        shifted[j] += h;
                        kind.radiance(&f, &exps(&shifted))[c] as f64
                    };
                    let numeric = (at(1e-3) - at(-1e-3)) / 2e-3;
                    assert!(
                        (numeric - d[j] as f64).abs() < 1e-3 * (1.0 + numeric.abs()),
                        "{kind:?} channel {c} output {j}: {} against {numeric}",
                        d[j]
                    );
                }
            }
        }
    }

    #[test]
    fn the_wgsl_table_lists_every_kind_by_code() {
        let table = kind_table_wgsl();
        assert!(table.contains("const MAX_TERMS: u32 = 2u;"), "{table}");
        assert!(table.contains("array<u32, 4>(1u, 2u, 1u, 1u)"), "{table}");
        let one = format!("{ONE_WEIGHT}u");
        let weights = format!(
            "array<u32, 2>({one}, {one}), array<u32, 2>(12u, 15u), array<u32, 2>(12u, {one}), \
             array<u32, 2>(15u, {one})"
        );
        assert!(table.contains(&weights), "{table}");
    }
}
