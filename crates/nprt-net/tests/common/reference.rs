//! The gradient checks' oracle, which needs no framework: a Neural PRT network's forward pass
//! and loss written plainly in f64 (no blocking, no shared products, no fused passes), on its
//! weights as f64 copies that finite differences can nudge below f32's resolution.

use nprt_net::encoding::hash_grid::{self, LEVEL_FEATURES};
use nprt_net::network::light_model::LightModel;
use nprt_net::network::mlp::Mlp;
use nprt_net::network::track_kind::Weight;
use nprt_net::{Activation, Batch, LightEntry, Loss, NprtNet, Parameters, FEATURES, OMEGA_0};

/// A network's structure and its weights in f64, one vector per tensor in visiting order.
pub struct Reference<'a> {
    net: &'a NprtNet,
    pub params: Vec<Vec<f64>>,
}

/// The tensors of one part of the network, taken in visiting order.
struct Tensors<'p>(std::slice::Iter<'p, Vec<f64>>);

impl<'p> Tensors<'p> {
    fn next(&mut self) -> &'p [f64] {
        self.0.next().expect("a tensor per weight")
    }
}

fn mlp(m: &Mlp, t: &mut Tensors, mut x: Vec<f64>) -> Vec<f64> {
    let n = m.layers.len();
    for (l, layer) in m.layers.iter().enumerate() {
        let (w, b) = (t.next(), t.next());
        let mut z = b.to_vec();
        for (i, xi) in x.iter().enumerate() {
            for (j, zj) in z.iter_mut().enumerate() {
                *zj += xi * w[i * layer.d_out + j];
            }
        }
        if l + 1 < n {
            for v in &mut z {
                *v = match m.activation {
                    Activation::Siren => (OMEGA_0 as f64 * *v).sin(),
                    Activation::Relu => v.max(0.0),
                };
            }
        }
        x = z;
    }
    x
}

impl<'a> Reference<'a> {
    pub fn new(net: &'a NprtNet) -> Self {
        let mut params = Vec::new();
        net.visit("", &mut |_, _, v| {
            params.push(v.iter().map(|&x| x as f64).collect())
        });
        Reference { net, params }
    }

    /// The light code of one map (3 × W/2 × W): the encoder's, or the basis' projection.
    fn code(&self, map: &[f64], width: usize, t: &mut Tensors) -> Vec<f64> {
        let encoder = match &self.net.light {
            LightModel::Encoder(e) => e,
            LightModel::Basis(b) => {
                let functions: Vec<f64> = match self.encoder_tensors() {
                    0 => b.functions.iter().map(|&v| v as f64).collect(),
                    _ => t.next().to_vec(),
                };
                return project(&functions, b.size(), map, width);
            }
        };
        let (mut h, mut w) = (width / 2, width);
        let mut x = map.to_vec();
        for conv in &encoder.convs {
            let (wt, bias) = (t.next(), t.next());
            let (c_in, c_out) = (conv.c_in, conv.c_out);
            let mut y = vec![0.0; c_out * h * w];
            for o in 0..c_out {
                for py in 0..h {
                    for px in 0..w {
                        let mut s = bias[o];
                        for c in 0..c_in {
                            for ky in 0..3 {
                                for kx in 0..3 {
                                    let (sy, sx) = (py + ky, px + kx);
                                    if sy < 1 || sx < 1 || sy > h || sx > w {
                                        continue;
                                    }
                                    let v = x[(c * h + sy - 1) * w + sx - 1];
                                    s += wt[((o * c_in + c) * 3 + ky) * 3 + kx] * v;
                                }
                            }
                        }
                        let skip = if o < c_in {
                            x[(o * h + py) * w + px]
                        } else {
                            0.0
                        };
                        y[(o * h + py) * w + px] = s.max(0.0) + skip;
                    }
                }
            }
            let (ph, pw) = (h / 2, w / 2);
            x = (0..c_out * ph * pw)
                .map(|i| {
                    let (c, py, px) = (i / (ph * pw), i / pw % ph, i % pw);
                    let at = |dy: usize, dx: usize| y[(c * h + 2 * py + dy) * w + 2 * px + dx];
                    at(0, 0).max(at(0, 1)).max(at(1, 0)).max(at(1, 1))
                })
                .collect();
            (h, w) = (ph, pw);
        }
        let (wt, bias) = (t.next(), t.next());
        let d_out = bias.len();
        (0..d_out)
            .map(|j| {
                bias[j]
                    + x.iter()
                        .enumerate()
                        .map(|(i, v)| v * wt[i * d_out + j])
                        .sum::<f64>()
            })
            .collect()
    }

    /// Every view's light code: for [`Self::predict`] and [`Self::loss`] while nudging
    /// tensors past the encoder's, made once.
    pub fn light_codes(&self, batch: &Batch) -> Vec<Vec<f64>> {
        let w = batch.light_width;
        (batch.lights.chunks(3 * w * w / 2))
            .map(|m| {
                let map: Vec<f64> = m.iter().map(|&v| v as f64).collect();
                self.code(&map, w, &mut Tensors(self.params.iter()))
            })
            .collect()
    }

    /// How many of the tensors are the light model's (they come first).
    pub fn encoder_tensors(&self) -> usize {
        match &self.net.light {
            LightModel::Encoder(e) => e.convs.len() * 2 + 2,
            LightModel::Basis(b) => b.choice.is_learned() as usize,
        }
    }

    /// Each sample's radiance (n × 3), its map's scale applied; with `codes`, those light
    /// codes instead of the encoder's (for nudges past the encoder).
    pub fn predict(&self, batch: &Batch, codes: Option<&[Vec<f64>]>) -> Vec<f64> {
        let own = codes.is_none().then(|| self.light_codes(batch));
        let codes = codes.or(own.as_deref()).expect("codes");
        let skip = self.encoder_tensors();
        let mut out = Vec::with_capacity(batch.len() * 3);
        for (s, f) in batch.features.chunks_exact(FEATURES).enumerate() {
            let code = &codes[batch.view[s] as usize];
            let mut t = Tensors(self.params[skip..].iter());
            let mut rgb = [0.0f64; 3];
            for track in &self.net.tracks {
                let mut x: Vec<f64> = track.kind.inputs().iter().map(|&i| f[i] as f64).collect();
                if track.grid.is_some() {
                    let table = t.next();
                    let c = hash_grid::corners(hash_grid::position(f));
                    let mut enc = vec![0.0; hash_grid::OUTPUTS];
                    for (k, (&row, &wgt)) in c.row.iter().zip(&c.weight).enumerate() {
                        let level = k / 8;
                        for q in 0..LEVEL_FEATURES {
                            enc[level * LEVEL_FEATURES + q] +=
                                wgt as f64 * table[row as usize * LEVEL_FEATURES + q];
                        }
                    }
                    x.extend(enc);
                }
                let outputs = match &track.transfer {
                    Some(ft) if matches!(track.light, LightEntry::Combine { .. }) => {
                        let s = mlp(ft, &mut t, x);
                        mlp(&track.shading, &mut t, s)
                    }
                    Some(ft) => {
                        let mut s = mlp(ft, &mut t, x);
                        s.extend_from_slice(code);
                        mlp(&track.shading, &mut t, s)
                    }
                    None if matches!(track.light, LightEntry::Combine { .. }) => {
                        mlp(&track.shading, &mut t, x)
                    }
                    None => {
                        let mut input = code.clone();
                        input.extend(x);
                        mlp(&track.shading, &mut t, input)
                    }
                };
                for (k, w) in track.kind.spec().terms.iter().enumerate() {
                    for c in 0..3 {
                        let weight = match *w {
                            Weight::One => 1.0,
                            Weight::Albedo(at) => f[at + c] as f64,
                        };
                        let term = match track.light {
                            LightEntry::FirstLayer { .. } => outputs[3 * k + c].exp(),
                            LightEntry::Combine { k: n } => (0..n)
                                .map(|j| outputs[(k * n + j) * 3 + c] * code[j * 3 + c])
                                .sum(),
                        };
                        rgb[c] += weight * term;
                    }
                }
            }
            out.extend((0..3).map(|c| rgb[c] * batch.scale[3 * s + c] as f64));
        }
        out
    }

    /// The batch's mean `loss`; the relative L2's weights held at `fixed` predictions (its
    /// gradient treats them as constants).
    pub fn loss(
        &self,
        batch: &Batch,
        loss: Loss,
        codes: Option<&[Vec<f64>]>,
        fixed: &[f64],
    ) -> f64 {
        let p = self.predict(batch, codes);
        let sum: f64 = (p.iter().zip(&batch.radiance).zip(fixed))
            .map(|((&p, &r), &q)| {
                let r = r as f64;
                match loss {
                    // Below 0, log(1 + p)'s tangent there (the linear design's radiance).
                    Loss::LogL1 => (if p >= 0.0 { p.ln_1p() } else { p } - r.ln_1p()).abs(),
                    Loss::RelL2 => {
                        (p - r).powi(2) / (q * q + nprt_net::loss::RELATIVE_L2_EPS as f64)
                    }
                }
            })
            .sum();
        sum / p.len() as f64
    }
}

/// A basis' code of one map: per function k and channel c at k·3 + c, the sum over texels of
/// the function's value × the texel's solid angle (exact for its band of latitude) × the map.
fn project(functions: &[f64], k: usize, map: &[f64], width: usize) -> Vec<f64> {
    let (h, texels) = (width / 2, width * width / 2);
    let pi = std::f64::consts::PI;
    let solid_angle = |t: usize| {
        let r = (t / width) as f64;
        2.0 * pi / width as f64 * ((pi * r / h as f64).cos() - (pi * (r + 1.0) / h as f64).cos())
    };
    let mut code = vec![0.0; 3 * k];
    for j in 0..k {
        for c in 0..3 {
            code[j * 3 + c] = (0..texels)
                .map(|t| functions[j * texels + t] * solid_angle(t) * map[c * texels + t])
                .sum();
        }
    }
    code
}
