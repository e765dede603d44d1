//! The Deep Shading U-Net on the CPU engine: its gradients against central differences of its
//! own loss, every tensor.
//!
//! The U-Net has no f64 reference beside it (the Neural PRT designs have, tests/net.rs): the
//! differences are of the engine's f32 loss, with steps large enough that f32 rounding stays
//! far below the change they make, so the check is at a percent, not at rounding. It catches
//! a gradient sent to the wrong layer, skip or level, or scaled wrongly.

#[allow(dead_code)] // the helpers other test binaries use
mod common;

use common::unet_batch;
use nprt_net::deep_shading::DeepShading;
use nprt_net::{Init, Loss, Parameters};

#[test]
fn unet_gradients_match_finite_differences() {
    let b = unet_batch(2, (8, 16), 3);
    let net = DeepShading::new(&mut Init::new(2), 64);
    let (loss, grads) = net.loss_and_gradients(&b, Loss::LogL1, true);
    let grads = grads.unwrap();
    assert!(loss.is_finite() && loss > 0.0);
    let mut engine = Vec::new();
    grads.visit("", &mut |name, _, v| {
        engine.push((name.to_string(), v.to_vec()))
    });
    let value = |net: &DeepShading| net.loss_and_gradients(&b, Loss::LogL1, false).0;
    let (mut checked, mut kinks) = (0, 0);
    for (t, (tensor, grad)) in engine.iter().enumerate() {
        let largest = (0..grad.len())
            .max_by(|&a, &b| grad[a].abs().total_cmp(&grad[b].abs()))
            .unwrap();
        let fd = |h: f32| {
            let nudged = |delta: f32| {
                let mut n = net.clone();
                let mut at = 0;
                n.visit_mut("", &mut |_, _, v| {
                    if at == t {
                        v[largest] += delta;
                    }
                    at += 1;
                });
                value(&n)
            };
            (nudged(h) - nudged(-h)) / (2.0 * h as f64)
        };
        let (coarse, fine) = (fd(2e-3), fd(1e-3));
        let ours = grad[largest] as f64;
        if (coarse - fine).abs() > 0.02 * fine.abs() + 1e-5 {
            kinks += 1;
            continue;
        }
        assert!(
            (fine - ours).abs() <= 0.02 * fine.abs().max(ours.abs()) + 2e-5,
            "{tensor} [{largest}]: engine {ours:e}, finite difference {fine:e}"
        );
        checked += 1;
    }
    // The light encoder, 6 + 2 + 3 + 1 convolutions and the code layer, each with a bias.
    assert_eq!(engine.len(), 12 + 2 * (6 + 2 + 3 + 1) + 2);
    assert!(
        checked >= 20 && kinks * 5 <= checked,
        "{checked} checked, {kinks} at a kink"
    );
}
