//! The GPU training step (nprt-net's own kernels, `gpu::GpuTrainer`) against the CPU engine
//! it must agree with: loss and every parameter's gradient (light encoder or learned basis,
//! transport networks, hash grids) for every design, the linear one included, activation and
//! encoding, both losses; two Adam steps against
//! the host's Adam. Overfitting and exact resume through `nprt train --device wgpu` are in nprt's
//! tests/train.rs. Runs on
//! whatever adapter wgpu finds; CI's is Mesa's software Vulkan (scripts/vulkan.sh). Without
//! one the tests skip, unless NPRT_REQUIRE_VULKAN is set (scripts/test sets it once lavapipe
//! is installed).
#![cfg(feature = "gpu")]

#[allow(dead_code)] // the helpers other test binaries use
mod common;

use common::{loud_grids, random_batch, relative_error, tensor_errors, update, variants, worst};
use nprt_gpu::GpuDevice;
use nprt_net::gpu::GpuTrainer;
use nprt_net::optimiser::Adam;
use nprt_net::{
    cpu, Activation, Design, Init, LightModel, Loss, ModelConfig, NprtNet, Parameters,
    PositionEncoding, Precision,
};

/// `config` with an encoder for the test batches' 64-wide maps, built from seed 4 with loud
/// grids.
fn network(config: &ModelConfig) -> NprtNet {
    let config = ModelConfig {
        encoder_width: 64,
        ..config.clone()
    };
    loud_grids(config.build(&mut Init::new(4)))
}

/// Every design, activation and encoding, and a network of three tracks ([`three_tracks`]).
#[test]
fn gpu_gradients_match_the_cpu_engine_for_every_design() {
    if !GpuDevice::probe() {
        return;
    }
    let batch = random_batch(300, 3, 22);
    let samples = batch.samples();
    let designs = variants().into_iter().map(|config| {
        let name = format!("{} {}", config.label(), config.activation);
        (name, network(&config))
    });
    for (name, net) in designs.chain([("three tracks".to_string(), three_tracks())]) {
        for loss in [Loss::LogL1, Loss::RelL2] {
            let (want_loss, want) = cpu::gradients(&net, &samples, loss);
            let mut gpu = GpuTrainer::new(&net, Precision::F32).unwrap();
            let value = gpu.backward(&samples, loss);
            let errors = tensor_errors(&gpu.gradients(), &want);
            let light_tensors = match &net.light {
                LightModel::Encoder(e) => 2 * e.convs.len() + 2,
                LightModel::Basis(b) => usize::from(b.choice.is_learned()),
            };
            let (light, transport) = errors.split_at(light_tensors);
            let loss_error = (value - want_loss).abs() / want_loss;
            let name = format!("{name} {loss}");
            eprintln!(
                "{name}: loss {loss_error:.1e}, light model gradients {:.1e}, transport gradients {:.1e}",
                worst(light),
                worst(transport)
            );
            // Lavapipe: loss within 6.7e-7, gradients within 1.2e-6 (sums in another order;
            // a GPU's sin and exp are its own).
            assert!(loss_error < 1e-5, "{name}: loss off by {loss_error}");
            assert!(
                worst(&errors) < 1e-4,
                "{name}: a gradient off by {errors:?}"
            );
            // The forward passes alone (validation) make the same loss, to the bit: they are
            // the same dispatches.
            assert_eq!(gpu.loss(&samples, loss), value, "{name}: forward-only loss");
        }
    }
}

/// Transfer targets (`--targets transfer`): the loss on the linear design's transfer vectors
/// and every gradient, on an SH basis with and without a hash grid, as the CPU engine makes
/// them; the forward passes alone make the same loss.
#[test]
fn gpu_gradients_on_transfer_vectors_match_the_cpu_engine() {
    if !GpuDevice::probe() {
        return;
    }
    let mut batch = random_batch(300, 3, 24);
    let k = 9;
    batch.transfer = (0..batch.len() * 3 * k)
        .map(|i| ((i * 37 % 101) as f32 / 101.0 - 0.3) * 0.5)
        .collect();
    let samples = batch.samples();
    for encoding in [PositionEncoding::None, PositionEncoding::HashGrid] {
        let net = network(&ModelConfig {
            basis: Some(nprt_net::BasisChoice::Sh { band: 2 }),
            encoding,
            ..ModelConfig::new(Design::Linear, None)
        });
        let (want_loss, want) = cpu::gradients(&net, &samples, Loss::LogL1);
        let mut gpu = GpuTrainer::new(&net, Precision::F32).unwrap();
        let value = gpu.backward(&samples, Loss::LogL1);
        let errors = tensor_errors(&gpu.gradients(), &want);
        let loss_error = (value - want_loss).abs() / want_loss;
        eprintln!(
            "transfer {encoding:?}: loss {loss_error:.1e}, gradients {:.1e}",
            worst(&errors)
        );
        assert!(loss_error < 1e-5, "{encoding:?}: loss off by {loss_error}");
        assert!(
            worst(&errors) < 1e-4,
            "{encoding:?}: a gradient off by {errors:?}"
        );
        assert_eq!(gpu.loss(&samples, Loss::LogL1), value, "forward-only loss");
    }
}

/// A network of three tracks, beyond every design (D/S's two and a full one): the kernels sum
/// and differentiate any number of tracks, one dispatch per track, as the CPU engine does.
fn three_tracks() -> NprtNet {
    let mut net = network(&ModelConfig::new(Design::Dsep, None));
    let (kind, encoding) = (nprt_net::TrackKind::Full, PositionEncoding::None);
    let third = nprt_net::Track::new(
        &mut Init::new(5),
        Design::Dsep,
        kind,
        Activation::Siren,
        encoding,
        Design::Dsep.entries(0)[0],
    );
    net.tracks.push(third);
    net
}

/// Two steps of the GPU's Adam against the host's Adam stepping on the CPU engine's gradients
/// (the CPU training path): what each moved every tensor by.
#[test]
fn gpu_adam_steps_match_the_hosts_adam_on_the_cpu_engine() {
    if !GpuDevice::probe() {
        return;
    }
    let batch = random_batch(300, 3, 23);
    let samples = batch.samples();
    let config = ModelConfig {
        encoding: PositionEncoding::HashGrid,
        encoder_width: 64,
        ..ModelConfig::new(Design::Dsep, None)
    };
    let mut net = loud_grids(config.build(&mut Init::new(4)));
    let start = net.clone();
    let mut gpu = GpuTrainer::new(&net, Precision::F32).unwrap();
    let mut adam = Adam::new(net.num_params());
    let lr = 1e-3;
    for _ in 0..2 {
        let (_, grads) = cpu::gradients(&net, &samples, Loss::LogL1);
        adam.step(&mut net, &grads, lr);
        gpu.step(&samples, Loss::LogL1, lr);
    }
    let errors = tensor_errors(&update(&gpu.parameters(), &start), &update(&net, &start));
    let worst = worst(&errors);
    eprintln!("largest relative difference of a tensor's update: {worst:.1e}");
    // Lavapipe: 2.5e-5. Adam's update m/√v magnifies the gradients' rounding where they are
    // near zero.
    assert!(worst < 1e-3, "updates differ: {errors:?}");
}

/// A profiled step (`nprt bench train --profile`) is the step: the same loss and parameters to
/// the bit as an untimed one, with each of its kernels timed, the plan's dispatches all
/// counted. Where the adapter has no timestamp queries it says so.
#[test]
fn a_profiled_step_is_a_step_with_its_kernels_timed() {
    if !GpuDevice::probe() {
        return;
    }
    let batch = random_batch(300, 3, 29);
    let samples = batch.samples();
    let net = network(&ModelConfig::new(Design::Dsep, None));
    let (mut plain, mut timed) = (
        GpuTrainer::new(&net, Precision::F32).unwrap(),
        GpuTrainer::new(&net, Precision::F32).unwrap(),
    );
    let lr = 1e-3;
    plain.step(&samples, Loss::LogL1, lr);
    let times = match timed.profile_step(&samples, Loss::LogL1, lr) {
        Ok(t) => t,
        Err(e) => {
            assert!(format!("{e:#}").contains("timestamp"), "{e:#}");
            eprintln!("skipped: {e:#}");
            return;
        }
    };
    let flat = |t: &GpuTrainer| t.parameters().flat();
    assert_eq!(
        flat(&plain),
        flat(&timed),
        "the profiled step computed something else"
    );
    let second = |t: &mut GpuTrainer| t.step(&samples, Loss::LogL1, lr);
    assert_eq!(
        second(&mut plain),
        second(&mut timed),
        "losses after the profiled step differ"
    );
    for kernel in ["gemm", "conv_weight_backward", "adam", "radiance_loss"] {
        assert!(
            times.iter().any(|k| k.kernel == kernel),
            "{kernel} untimed: {times:?}"
        );
    }
    assert_eq!(
        times
            .iter()
            .filter(|k| k.kernel == "adam")
            .map(|k| k.dispatches)
            .sum::<usize>(),
        1
    );
    assert!(
        times.iter().all(|k| k.ms >= 0.0) && times.iter().any(|k| k.ms > 0.0),
        "{times:?}"
    );
    assert!(
        times.windows(2).all(|w| w[0].ms >= w[1].ms),
        "not longest first: {times:?}"
    );
}

/// Mixed precision (`Precision::F16`: the transport networks' products on f16 operands, sums
/// in f32, the loss's gradient scaled) against the CPU engine's f32: loss and every
/// parameter's gradient for every design, activation and encoding, both losses. Lavapipe runs
/// the plain kernels, which compute the tensor-core kernels' sums (in another order).
#[test]
fn mixed_precision_gradients_follow_the_cpu_engine_for_every_design() {
    if !GpuDevice::probe() {
        return;
    }
    if !GpuDevice::get().unwrap().half {
        eprintln!("skipped: the adapter has no f16 in shaders");
        return;
    }
    let batch = random_batch(300, 3, 22);
    let samples = batch.samples();
    let mut worst_loss = 0.0f64;
    let mut worst_gradient = 0.0f64;
    // A basis of 96 makes the linear design's last layer 288 wide, more than a fused pass
    // holds (256): its MLP runs a layer a dispatch, forward and backward.
    let wide = ModelConfig {
        basis: Some(nprt_net::BasisChoice::Learned { size: 96 }),
        ..ModelConfig::new(Design::Linear, None)
    };
    for config in variants().into_iter().chain([wide]) {
        let net = network(&config);
        for loss in [Loss::LogL1, Loss::RelL2] {
            let (want_loss, want) = cpu::gradients(&net, &samples, loss);
            let mut gpu = GpuTrainer::new(&net, Precision::F16).unwrap();
            let value = gpu.backward(&samples, loss);
            let errors = tensor_errors(&gpu.gradients(), &want);
            let worst = worst(&errors);
            let loss_error = (value - want_loss).abs() / want_loss;
            let name = format!("{} {} {loss}", config.label(), config.activation);
            eprintln!("{name}: loss {loss_error:.1e}, gradients {worst:.1e}");
            worst_loss = worst_loss.max(loss_error);
            worst_gradient = worst_gradient.max(worst);
        }
    }
    eprintln!(
        "mixed precision: loss within {worst_loss:.1e}, gradients within {worst_gradient:.1e}"
    );
    // Lavapipe: loss within 1.1e-2 (PRT, relative L2), gradients within 8.7e-2 (the first
    // SIREN layer after a hash grid, whose ω0 = 30 magnifies its inputs' rounding; most
    // tensors 1e-3 to 2e-2). A wrong layout or copy is off by the gradient's own size.
    assert!(worst_loss < 2e-2, "loss off by {worst_loss}");
    assert!(worst_gradient < 0.15, "a gradient off by {worst_gradient}");
}

/// Mixed-precision steps follow f32 steps: three Adam steps at a large rate from one network
/// move the loss by far more than the two runs then differ by, and move the parameters alike.
/// It also shows that the f16 copies of the weights follow Adam: stale copies would leave the
/// mixed-precision loss where it started.
#[test]
fn mixed_precision_steps_follow_f32_steps() {
    if !GpuDevice::probe() || !GpuDevice::get().unwrap().half {
        return;
    }
    let batch = random_batch(300, 3, 24);
    let samples = batch.samples();
    let config = ModelConfig {
        encoding: PositionEncoding::HashGrid,
        ..ModelConfig::new(Design::Dsep, None)
    };
    let net = network(&config);
    let [mut full, mut mixed] =
        [Precision::F32, Precision::F16].map(|p| GpuTrainer::new(&net, p).unwrap());
    let before = full.loss(&samples, Loss::LogL1);
    for _ in 0..3 {
        full.step(&samples, Loss::LogL1, 1e-3);
        mixed.step(&samples, Loss::LogL1, 1e-3);
    }
    let [after_full, after_mixed] = [&mut full, &mut mixed].map(|t| t.loss(&samples, Loss::LogL1));
    let moved = (after_full - before).abs();
    let apart = (after_mixed - after_full).abs();
    let updated = |t: &GpuTrainer| update(&t.parameters(), &net).flat();
    let updates = relative_error(&updated(&mixed), &updated(&full));
    eprintln!(
        "loss {before:.5} → {after_full:.5} (f32), {after_mixed:.5} (mixed); updates apart by \
         {updates:.1e}"
    );
    assert!(
        apart < 0.01 * moved,
        "the mixed-precision run went elsewhere"
    );
    // Lavapipe: the losses 7·10⁻⁴ of the move apart, the updates 6.6·10⁻²: Adam's update
    // m/√v magnifies the rounding of gradients near zero.
    assert!(updates < 0.2, "updates apart by {updates}");
}
