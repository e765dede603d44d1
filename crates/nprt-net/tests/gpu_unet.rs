//! The Deep Shading U-Net on the GPU kernels (`gpu::GpuUnet`) against the CPU engine it must
//! agree with: the loss and every tensor's gradient under both losses, the frames it shades,
//! two Adam steps against the host's Adam, and a resumed run continuing to the bit. Runs on
//! whatever adapter wgpu finds (CI's is lavapipe); without one the tests skip, unless
//! NPRT_REQUIRE_VULKAN is set.
#![cfg(feature = "gpu")]

#[allow(dead_code)] // the helpers other test binaries use
mod common;

use common::{relative_error, tensor_errors, unet_batch, update, worst};
use nprt_gpu::GpuDevice;
use nprt_net::deep_shading::DeepShading;
use nprt_net::gpu::GpuUnet;
use nprt_net::optimiser::Adam;
use nprt_net::{Init, Loss, Parameters};

/// A U-Net for the test batches' 64-wide maps.
fn network() -> DeepShading {
    DeepShading::new(&mut Init::new(2), 64)
}

#[test]
fn gpu_unet_gradients_match_the_cpu_engine() {
    if !GpuDevice::probe() {
        return;
    }
    // Three levels down from 16 × 24 leave 2 × 3 at the bottleneck.
    let batch = unet_batch(2, (16, 24), 5);
    let net = network();
    let mut gpu = GpuUnet::new(&net).unwrap();
    for loss in [Loss::LogL1, Loss::RelL2] {
        let (want_loss, want) = net.loss_and_gradients(&batch, loss, true);
        let value = gpu.backward(&batch, loss);
        let errors = tensor_errors(&gpu.gradients(), &want.unwrap());
        let loss_error = (value - want_loss).abs() / want_loss;
        eprintln!(
            "{loss}: loss {loss_error:.1e}, gradients {:.1e}",
            worst(&errors)
        );
        assert!(loss_error < 1e-5, "{loss}: loss off by {loss_error}");
        assert!(worst(&errors) < 1e-4, "{loss}: a gradient off: {errors:?}");
        // The forward pass alone (validation) makes the same loss, to the bit.
        assert_eq!(gpu.loss(&batch, loss), value, "{loss}: forward-only loss");
    }
}

#[test]
fn gpu_unet_shades_as_the_cpu_engine() {
    if !GpuDevice::probe() {
        return;
    }
    let batch = unet_batch(2, (16, 24), 6);
    let net = network();
    let frames = GpuUnet::new(&net).unwrap().shade(&batch);
    let (hw, light) = (16 * 24, 3 * 64 * 32);
    let fd = nprt_net::FEATURES * hw;
    for v in 0..2 {
        let want = net.shade(
            &batch.features[v * fd..][..fd],
            &batch.lights[v * light..][..light],
            64,
            [0, 1, 2].map(|c| batch.scale[3 * v + c]),
            (16, 24),
        );
        let error = relative_error(&frames[v * 3 * hw..][..3 * hw], &want);
        eprintln!("view {v}: {error:.1e}");
        assert!(error < 1e-5, "view {v} off by {error}");
    }
}

#[test]
fn gpu_unet_adam_steps_match_the_hosts_adam_and_resume_exactly() {
    if !GpuDevice::probe() {
        return;
    }
    let batch = unet_batch(2, (16, 24), 7);
    let start = network();
    let mut net = start.clone();
    let mut gpu = GpuUnet::new(&net).unwrap();
    let mut adam = Adam::new(net.num_params());
    let lr = 1e-3;
    for _ in 0..2 {
        let (_, grads) = net.loss_and_gradients(&batch, Loss::LogL1, true);
        adam.step(&mut net, &grads.unwrap(), lr);
        gpu.step(&batch, Loss::LogL1, lr);
    }
    let errors = tensor_errors(&update(&gpu.parameters(), &start), &update(&net, &start));
    eprintln!(
        "largest relative difference of a tensor's update: {:.1e}",
        worst(&errors)
    );
    // Adam's update m/√v magnifies the gradients' rounding where they are near zero.
    assert!(worst(&errors) < 1e-3, "updates differ: {errors:?}");

    // Adam's state written by the kernels and read back into a fresh trainer: the next step
    // is the one the first trainer takes, to the bit.
    let dir = std::env::temp_dir().join(format!("nprt-gpu-unet-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let state = dir.join("adam.safetensors");
    gpu.save_state(&state).unwrap();
    let mut resumed = GpuUnet::new(&gpu.parameters()).unwrap();
    resumed.load_state(&state).unwrap();
    let (a, b) = (
        gpu.step(&batch, Loss::LogL1, lr),
        resumed.step(&batch, Loss::LogL1, lr),
    );
    assert_eq!(a, b, "the resumed step's loss");
    assert_eq!(gpu.parameters().flat(), resumed.parameters().flat());
    // The host's Adam reads the same file.
    adam.load(&state).unwrap();
    std::fs::remove_dir_all(&dir).ok();
}
