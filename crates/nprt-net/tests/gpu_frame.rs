//! The GPU frame path's kernels (`gpu::GpuNetwork`) against the CPU engine they must agree with:
//! light codes and radiance of every design, both activations, with and without the hash
//! grid, on a real G-buffer. Runs on whatever adapter wgpu finds; CI's is Mesa's software
//! Vulkan (scripts/vulkan.sh). Without one the tests skip, unless NPRT_REQUIRE_VULKAN is set
//! (scripts/test sets it once lavapipe is installed).
#![cfg(feature = "gpu")]

use glam::Vec3;
use nprt_gpu::GpuDevice;
use nprt_net::gpu::{GpuLightCode, GpuLightInput, GpuNetwork};
use nprt_net::{
    gbuffer_features, Activation, Design, Init, LightInput, MapNorm, ModelConfig, NprtNet,
    PositionEncoding,
};
use nprt_scene::{load_scene, Camera, SceneOptions};
use nprt_trace::{render_gbuffer, TraceScene};

/// The network inputs of the foreground pixels of a 40 × 30 view of the built-in room.
fn room_features() -> Vec<f32> {
    let scene = load_scene("builtin:room", &SceneOptions::default()).unwrap();
    let ts = TraceScene::new(&scene);
    let (lo, hi) = scene.bounds();
    let bounds = [lo.to_array(), hi.to_array()];
    let eye = lo + (hi - lo) * Vec3::new(0.5, 0.6, 0.8);
    let target = lo + (hi - lo) * Vec3::new(0.4, 0.3, 0.1);
    let camera = Camera::look_at(eye, target, Vec3::Y, 70.0, 40, 30);
    let g = render_gbuffer(&ts, &camera);
    (0..g.mask.len())
        .filter(|&i| g.mask[i] > 0.5)
        .flat_map(|i| gbuffer_features(&bounds, &g, i))
        .collect()
}

/// Largest |a − b| over the largest |b|.
fn relative_difference(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f32, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// An untrained network, its hash grids (if any) scaled to values of order one so that the
/// encoding weighs in the output as in a trained network (an untrained grid holds ±1e-4).
fn model(design: Design, activation: Activation, encoding: PositionEncoding, seed: u64) -> NprtNet {
    let config = ModelConfig {
        encoder_width: 64,
        encoding,
        ..ModelConfig::new(design, Some(activation))
    };
    let mut net = config.build(&mut Init::new(seed));
    for grid in net.tracks.iter_mut().filter_map(|t| t.grid.as_mut()) {
        grid.table.iter_mut().for_each(|v| *v *= 1e4);
    }
    net
}

#[test]
fn gpu_light_codes_and_radiance_match_the_cpu_engine_for_every_design() {
    if !GpuDevice::probe() {
        return;
    }
    let device = GpuDevice::get().unwrap();
    let features = room_features();
    assert!(features.len() > 19 * 500, "the view sees the room");
    let map = nprt_scene::open_envmap("builtin:sky:25:40").unwrap();
    let input = LightInput::new(&map, 30.0, 64, MapNorm::Channel);
    // The radiance's scale per channel: a map's divisor times the model's gain.
    let (divisor, gain) = ([0.5, 3.0, 1.0], [4.0, 1.0, 0.5]);
    let scale = [2.0, 3.0, 0.5];
    let mut seed = 0;
    for design in [Design::Baseline, Design::Prt, Design::Albedo, Design::Dsep] {
        for activation in [Activation::Relu, Activation::Siren] {
            for encoding in [PositionEncoding::None, PositionEncoding::HashGrid] {
                seed += 1;
                let net = model(design, activation, encoding, seed);
                let gpu = GpuNetwork::new(&net, gain, 64, MapNorm::Channel).unwrap();
                let there = gpu.light_code(&GpuLightInput::upload(&device, &input));
                let (code, _) = there.read(&device);
                let want_code = net.encoder().unwrap().forward(&input.pixels, 64).codes;
                let code_error = relative_difference(&code, &want_code);
                let light = GpuLightCode::upload(&device, &want_code, divisor);
                let rgb = gpu.radiance(&gpu.pixels(&features), &light);
                let want = net.radiance(&features, &want_code, scale, None);
                let error = relative_difference(&rgb, &want);
                eprintln!(
                    "{design} {activation} {encoding}: code {code_error:.2e}, radiance {error:.2e}"
                );
                // Lavapipe: at most 3e-7 and 1.4e-6 (the sums run in another order).
                assert!(
                    code_error < 3e-6,
                    "{design} {activation} {encoding}: light code off by {code_error}"
                );
                assert!(
                    error < 1e-5,
                    "{design} {activation} {encoding}: radiance off by {error}"
                );
            }
        }
    }
}

/// A network of three tracks, beyond every design (D/S's two and a full one): the frame path
/// sums any number of tracks, one `combine` per track, as the CPU engine does.
#[test]
fn three_tracks_shade_as_on_the_cpu_engine() {
    if !GpuDevice::probe() {
        return;
    }
    let device = GpuDevice::get().unwrap();
    let features = room_features();
    let mut net = model(
        Design::Dsep,
        Activation::Siren,
        PositionEncoding::HashGrid,
        40,
    );
    let kind = nprt_net::TrackKind::Full;
    let third = nprt_net::Track::new(
        &mut Init::new(41),
        Design::Dsep,
        kind,
        Activation::Siren,
        PositionEncoding::None,
        Design::Dsep.entries(0)[0],
    );
    net.tracks.push(third);
    let (divisor, gain) = ([0.5, 3.0, 1.0], [4.0, 1.0, 0.5]);
    let gpu = GpuNetwork::new(&net, gain, 64, MapNorm::Channel).unwrap();
    let map = nprt_scene::open_envmap("builtin:sky:25:40").unwrap();
    let input = LightInput::new(&map, 30.0, 64, MapNorm::Channel);
    let code = net.encoder().unwrap().forward(&input.pixels, 64).codes;
    let light = GpuLightCode::upload(&device, &code, divisor);
    let rgb = gpu.radiance(&gpu.pixels(&features), &light);
    let want = net.radiance(&features, &code, [2.0, 3.0, 0.5], None);
    let error = relative_difference(&rgb, &want);
    eprintln!("three tracks: radiance {error:.2e}");
    assert!(error < 1e-5, "three tracks: radiance off by {error}");
}

#[test]
fn the_widest_encoder_input_gets_the_cpu_engines_light_code() {
    if !GpuDevice::probe() {
        return;
    }
    // 1024 wide: the first block's 65,536 workgroups need a second dimension.
    let width = nprt_net::network::encoder::MAX_INPUT_WIDTH;
    let config = ModelConfig {
        encoder_width: width,
        ..ModelConfig::new(Design::Prt, None)
    };
    let net = config.build(&mut Init::new(7));
    let map = nprt_scene::open_envmap("builtin:indoor:4").unwrap();
    let input = LightInput::new(&map, 0.0, width, MapNorm::Channel);
    let device = GpuDevice::get().unwrap();
    let input_there = GpuLightInput::upload(&device, &input);
    let gpu = GpuNetwork::new(&net, [1.0; 3], 64, MapNorm::Channel).unwrap();
    let (code, _) = gpu.light_code(&input_there).read(&device);
    let want = net.encoder().unwrap().forward(&input.pixels, width).codes;
    let error = relative_difference(&code, &want);
    assert!(error < 3e-6, "light code off by {error}");
}

/// The encoder's input made on the device from the map (`GpuNetwork::light_input`, what frames
/// on the kernels use) against `LightInput::new` on the host: skies with a sun, an indoor map and
/// a map placed tilted (a scene file's own transform), rotated, under both normalisations, at
/// encoder widths whose lookups per texel differ. Each map is dropped before the next is
/// loaded, which may take its texels' address: the texels kept on the device must not be the
/// dropped map's. The light codes it gives follow the CPU engine's.
#[test]
fn the_encoder_input_made_on_the_device_is_the_hosts() {
    if !GpuDevice::probe() {
        return;
    }
    let device = GpuDevice::get().unwrap();
    let net = model(Design::Dsep, Activation::Siren, PositionEncoding::None, 3);
    let gpu = GpuNetwork::new(&net, [1.0; 3], 64, MapNorm::Channel).unwrap();
    let encoder = net.encoder().unwrap();
    let maps = [
        ("builtin:sky:25:40", false, 64, 30.0, MapNorm::Channel),
        ("builtin:sky:60:200:3", false, 64, -145.0, MapNorm::Mean),
        ("builtin:indoor:4", false, 32, 90.0, MapNorm::Channel),
        ("builtin:sky:40:100", true, 64, 12.5, MapNorm::Mean),
    ];
    let mut worst = 0.0f32;
    for (spec, tilted, width, rotation, norm) in maps {
        let mut map = nprt_scene::open_envmap(spec).unwrap();
        if tilted {
            map = map.with_to_world(glam::Mat3::from_rotation_x(0.3) * map.to_world());
        }
        let want = LightInput::new(&map, rotation, width, norm);
        let there = gpu.light_input(&map, rotation, width, norm);
        let got = there.read(&device);
        let pixels = relative_difference(&got.pixels, &want.pixels);
        let scale = relative_difference(&got.scale, &want.scale);
        eprintln!("{spec} at {width}, {rotation}°, {norm}: pixels {pixels:.2e}, scale {scale:.2e}");
        assert!(
            pixels < 1e-5 && scale < 1e-5,
            "{spec}: pixels {pixels}, scale {scale}"
        );
        if width == 64 {
            let (code, code_scale) = gpu.light_code(&there).read(&device);
            let want_code = encoder.forward(&want.pixels, 64).codes;
            let error = relative_difference(&code, &want_code);
            assert!(error < 1e-5, "{spec}: light code off by {error}");
            assert_eq!(code_scale, got.scale);
            worst = worst.max(error);
        }
    }
    eprintln!("light codes within {worst:.2e}");
}

/// The networks in half precision (`--precision f16`: f16 weights and activations, f32 sums)
/// against the CPU engine's f32, every design, both activations, with and without the hash
/// grid, over a row count that is no multiple of the kernels' 256-row blocks. On an adapter
/// with tensor cores this runs the cooperative-matrix product, elsewhere the plain one.
#[test]
fn half_precision_radiance_follows_the_cpu_engines_for_every_design() {
    if !GpuDevice::probe() {
        return;
    }
    let features = room_features();
    let map = nprt_scene::open_envmap("builtin:sky:25:40").unwrap();
    let input = LightInput::new(&map, 30.0, 64, MapNorm::Channel);
    let scale = [2.0, 1.0, 0.5];
    let device = GpuDevice::get().unwrap();
    let mut seed = 100;
    let mut worst = 0.0f32;
    for design in [Design::Baseline, Design::Prt, Design::Albedo, Design::Dsep] {
        for activation in [Activation::Relu, Activation::Siren] {
            for encoding in [PositionEncoding::None, PositionEncoding::HashGrid] {
                seed += 1;
                let net = model(design, activation, encoding, seed);
                let mut gpu = GpuNetwork::new(&net, [1.0; 3], 64, MapNorm::Channel).unwrap();
                gpu.set_half(true).unwrap();
                let code = net.encoder().unwrap().forward(&input.pixels, 64).codes;
                let light = GpuLightCode::upload(&device, &code, scale);
                let rgb = gpu.radiance(&gpu.pixels(&features), &light);
                let want = net.radiance(&features, &code, scale, None);
                let error = mean_relative_difference(&rgb, &want);
                eprintln!(
                    "{design} {activation} {encoding} ({}): mean error {error:.2e}",
                    gpu.precision_name()
                );
                worst = worst.max(error);
            }
        }
    }
    assert!(worst < 1e-2, "half precision off by {worst} of the mean");
}

/// Mean |a − b| over the mean |b|.
fn mean_relative_difference(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    let diff: f32 = a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum();
    diff / b.iter().map(|v| v.abs()).sum::<f32>()
}

/// The tensor-core products, which an adapter without cooperative matrices (Mesa's software
/// Vulkan) cannot run, validated and translated to SPIR-V as wgpu does for a GPU that has them:
/// the frame path's (`half_dense_coop`) and a mixed-precision training step's (the same
/// product under the training epilogue, and the weight gradient). naga 30's writer panicked on
/// a stored matrix or an offset not bound by `let`, which the kernels avoid. Their arithmetic
/// is checked against the CPU engine on such a GPU by
/// `half_precision_radiance_follows_the_cpu_engines_for_every_design` and nprt-net's
/// `mixed_precision_gradients_follow_the_cpu_engine_for_every_design`.
#[test]
fn the_tensor_core_kernels_translate_to_spirv() {
    use nprt_net::gpu::kernels::{
        HALF_DENSE_COOP, HALF_MLP_COOP, HALF_TRAIN_COOP, HALF_WEIGHT_GRAD_COOP,
    };
    for kernel in [
        &HALF_DENSE_COOP,
        &HALF_MLP_COOP,
        &HALF_TRAIN_COOP,
        &HALF_WEIGHT_GRAD_COOP,
    ] {
        let module = naga::front::wgsl::parse_str(kernel.wgsl)
            .unwrap_or_else(|e| panic!("{}: {}", kernel.name, e.emit_to_string(kernel.wgsl)));
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}: {}", kernel.name, e.emit_to_string(kernel.wgsl)));
        let words = naga::back::spv::write_vec(&module, &info, &Default::default(), None).unwrap();
        assert!(
            words.len() > 1000,
            "{}: {} SPIR-V words",
            kernel.name,
            words.len()
        );
    }
}

/// A second viewpoint of the same size reuses the first one's buffers (features, ŝ, the frame,
/// handed back when its pixels are dropped) and the network's activations, in f32 and in f16:
/// its radiance is the radiance a fresh network gives it.
#[test]
fn a_new_viewpoint_reusing_the_last_ones_buffers_gets_its_own_radiance() {
    if !GpuDevice::probe() {
        return;
    }
    let first = room_features();
    // Another view of as many pixels: the rows reversed.
    let second: Vec<f32> = first
        .chunks(nprt_net::FEATURES)
        .rev()
        .flatten()
        .copied()
        .collect();
    let net = model(
        Design::Dsep,
        Activation::Siren,
        PositionEncoding::HashGrid,
        41,
    );
    let code = vec![0.25f32; nprt_net::network::encoder::CODE_SIZE];
    let light = GpuLightCode::upload(&GpuDevice::get().unwrap(), &code, [1.0, 2.0, 0.5]);
    for half in [false, true] {
        let mut reused = GpuNetwork::new(&net, [1.0; 3], 64, MapNorm::Channel).unwrap();
        let mut fresh = GpuNetwork::new(&net, [1.0; 3], 64, MapNorm::Channel).unwrap();
        reused.set_half(half).unwrap();
        fresh.set_half(half).unwrap();
        drop(reused.pixels(&first));
        let got = reused.radiance(&reused.pixels(&second), &light);
        let want = fresh.radiance(&fresh.pixels(&second), &light);
        assert_eq!(got, want, "half precision: {half}");
    }
}

/// The linear design on the frame path: its light code (the map made into the basis' input and
/// projected, all on the device) and its radiance agree with the CPU engine's, for the fixed
/// basis and a learned one, and a frame under a·E₁ + b·E₂ is a·(the frame under E₁) +
/// b·(under E₂) to rounding, as on the CPU engine; in half precision within 1% of the mean.
#[test]
fn the_linear_design_shades_as_on_the_cpu_engine() {
    if !GpuDevice::probe() {
        return;
    }
    let device = GpuDevice::get().unwrap();
    let features = room_features();
    let sky = nprt_scene::open_envmap("builtin:sky:25:40").unwrap();
    let gain = [4.0, 1.0, 0.5];
    for (seed, basis) in [(50, "sh:2"), (51, "learned:8")] {
        let config = ModelConfig {
            encoder_width: 64,
            basis: Some(basis.parse().unwrap()),
            ..ModelConfig::new(Design::Linear, None)
        };
        let net = config.build(&mut Init::new(seed));
        let gpu = GpuNetwork::new(&net, gain, 64, MapNorm::Channel).unwrap();
        let px = gpu.pixels(&features);
        let frame = |map: &nprt_scene::EnvMap| {
            let code = gpu.encode_map(map, 30.0, 64, MapNorm::Channel);
            (code.read(&device), gpu.radiance(&px, &code))
        };
        let ((code, divisor), rgb) = frame(&sky);
        let input = config.light_input(&sky, 30.0);
        let want_code = net.light.forward(&input.pixels, 64).codes().to_vec();
        let scale = std::array::from_fn(|k| input.scale[k] * gain[k]);
        let want = net.radiance(&features, &want_code, scale, None);
        let (code_error, error) = (
            relative_difference(&code, &want_code),
            relative_difference(&rgb, &want),
        );
        eprintln!("linear {basis}: code {code_error:.2e}, radiance {error:.2e}");
        // The divisor: the map's mean, summed in f32 on the device and in f64 on the host.
        let divisor_error = relative_difference(&divisor, &input.scale);
        assert!(
            divisor_error < 1e-6,
            "{basis}: divisor off by {divisor_error}"
        );
        assert!(code_error < 1e-5, "{basis}: light code off by {code_error}");
        assert!(error < 1e-5, "{basis}: radiance off by {error}");

        // Linearity through the whole device path (input, projection, networks, combine).
        let (a, b) = (0.3f32, 2.5f32);
        let room = nprt_scene::open_envmap("builtin:indoor:3").unwrap();
        assert_eq!(room.width(), sky.width(), "maps of one size, to add");
        let texels = (sky.texels().iter().zip(room.texels()))
            .map(|(x, y)| *x * a + *y * b)
            .collect();
        let (w, h) = (sky.width(), sky.height());
        let mixed = nprt_scene::EnvMap::from_texels("mix", w, h, texels).unwrap();
        let (_, one) = frame(&sky);
        let (_, two) = frame(&room);
        let (_, both) = frame(&mixed);
        let sum: Vec<f32> = one.iter().zip(&two).map(|(x, y)| a * x + b * y).collect();
        let error = relative_difference(&both, &sum);
        eprintln!("linear {basis}: mixture {error:.2e}");
        assert!(error < 1e-5, "{basis}: a mixture's frame off by {error}");

        // In half precision: the kept transfer coefficients made from f16 activations.
        let mut half = GpuNetwork::new(&net, gain, 64, MapNorm::Channel).unwrap();
        half.set_half(true).unwrap();
        let code = half.encode_map(&sky, 30.0, 64, MapNorm::Channel);
        let rgb = half.radiance(&half.pixels(&features), &code);
        let error = mean_relative_difference(&rgb, &want);
        eprintln!(
            "linear {basis} ({}): mean error {error:.2e}",
            half.precision_name()
        );
        assert!(
            error < 1e-2,
            "{basis}: half precision off by {error} of the mean"
        );
    }
}

/// A design mixing the light's two entries (linear-diffuse: its diffuse track at the combine,
/// its specular track's first layer reading the same projection) shades as on the CPU engine,
/// in f32 and f16, under a first lighting and a second one on the pixels the first kept (a
/// lighting change runs the combine for one track and the shading network for the other).
#[test]
fn a_design_mixing_the_lights_entries_shades_as_on_the_cpu_engine() {
    if !GpuDevice::probe() {
        return;
    }
    let device = GpuDevice::get().unwrap();
    let features = room_features();
    let gain = [4.0, 1.0, 0.5];
    let maps =
        ["builtin:sky:25:40", "builtin:indoor:3"].map(|m| nprt_scene::open_envmap(m).unwrap());
    for (seed, basis) in [(52, "sh:2"), (53, "learned:8")] {
        let config = ModelConfig {
            encoder_width: 64,
            basis: Some(basis.parse().unwrap()),
            ..ModelConfig::new(Design::LinearDiffuse, None)
        };
        let net = config.build(&mut Init::new(seed));
        for half in [false, true] {
            let mut gpu = GpuNetwork::new(&net, gain, 64, MapNorm::Channel).unwrap();
            gpu.set_half(half).unwrap();
            let px = gpu.pixels(&features);
            for map in &maps {
                let code = gpu.encode_map(map, 30.0, 64, MapNorm::Channel);
                let rgb = gpu.radiance(&px, &code);
                let input = config.light_input(map, 30.0);
                let want_code = net.light.forward(&input.pixels, 64).codes().to_vec();
                let code_error = relative_difference(&code.read(&device).0, &want_code);
                let scale = std::array::from_fn(|k| input.scale[k] * gain[k]);
                let want = net.radiance(&features, &want_code, scale, None);
                let name = format!("{basis} {} {}", gpu.precision_name(), map.name());
                assert!(code_error < 1e-5, "{name}: light code off by {code_error}");
                if half {
                    let error = mean_relative_difference(&rgb, &want);
                    eprintln!("linear-diffuse {name}: mean error {error:.2e}");
                    assert!(error < 1e-2, "{name}: off by {error} of the mean");
                } else {
                    let error = relative_difference(&rgb, &want);
                    eprintln!("linear-diffuse {name}: code {code_error:.2e}, radiance {error:.2e}");
                    assert!(error < 1e-5, "{name}: radiance off by {error}");
                }
            }
        }
    }
}
