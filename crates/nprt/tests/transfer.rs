//! Transfer vectors as users make and learn them: `nprt generate --transfer sh:L` against the
//! path tracer's radiance and the SH PRT baseline's transport of the same views, and
//! `nprt train --targets transfer` with the pairings it refuses.

mod common;

use std::path::Path;

use common::{fails, fresh_dir, ok};
use glam::Vec3;
use nprt_data::dataset::{load_manifest, load_manifest_hashed, relit, PackedDataset, PackedTarget};
use nprt_data::views::load_view;
use nprt_eval::sh::{project, ShTransport};
use nprt_scene::{load_scene, open_envmap};
use nprt_trace::{PixelFilter, RenderSettings, TraceScene};

/// A map's file name, its brightness by direction and its colour.
type SmoothMap = (&'static str, fn(Vec3) -> f32, Vec3);

/// Two maps that bands 0 and 1 hold exactly (so SH bands 0..2 relight them without loss),
/// each a different colour, in `dir`.
fn smooth_maps(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let (w, h) = (128, 64);
    let maps: [SmoothMap; 2] = [
        ("above.exr", |d| 1.0 + 0.8 * d.y, Vec3::new(1.0, 0.8, 0.6)),
        ("aside.exr", |d| 1.0 + 0.6 * d.x, Vec3::new(0.5, 0.7, 1.0)),
    ];
    for (name, f, colour) in maps {
        let texels: Vec<Vec3> = (0..w * h)
            .map(|i| {
                let uv = glam::Vec2::new(
                    ((i % w) as f32 + 0.5) / w as f32,
                    ((i / w) as f32 + 0.5) / h as f32,
                );
                colour * f(nprt_scene::envmap::uv_to_direction(uv))
            })
            .collect();
        let channels: Vec<(String, Vec<f32>)> = ["R", "G", "B"]
            .iter()
            .enumerate()
            .map(|(c, n)| (n.to_string(), texels.iter().map(|t| t[c]).collect()))
            .collect();
        nprt_io::exr::write_channels(&dir.join(name), w, h, &channels).unwrap();
    }
}

/// A dataset of builtin:room under the two smooth maps (one held out), its two training
/// views with transfer vectors on sh:2.
fn transfer_dataset(name: &str) -> std::path::PathBuf {
    let root = fresh_dir(name);
    smooth_maps(&root.join("maps"));
    let data = root.join("data");
    ok(&[
        "generate",
        "--scene",
        "builtin:room",
        "--envmaps",
        root.join("maps").to_str().unwrap(),
        "--test-maps",
        "1",
        "--mix-builtin",
        "0",
        "--train-views",
        "2",
        "--test-views",
        "1",
        "--train-res",
        "24",
        "--test-res",
        "16",
        "--spp",
        "256",
        "--test-spp",
        "8",
        "--seed",
        "1",
        "--transfer",
        "sh:2",
        "--out",
        data.to_str().unwrap(),
    ]);
    data
}

/// Relit by their lighting's SH coefficients, the recorded transfer vectors give the radiance
/// (and its direct part) the path tracer rendered with light sampling, within noise: a check of
/// the recording, the file's channels and the basis' orientation at once. And they agree with
/// the SH PRT baseline's transport of the same pixels, traced from other paths.
#[test]
fn transfer_vectors_relight_their_view_as_the_path_tracer_and_agree_with_sh_prt() {
    let data = transfer_dataset("transfer-relight");
    let manifest = load_manifest(&data).unwrap();
    assert_eq!(manifest.settings.transfer.unwrap().to_string(), "sh:2");
    let maps: Vec<_> = (manifest.settings.envmaps.iter())
        .map(|m| open_envmap(&m.spec).unwrap())
        .collect();
    let scene = load_scene("builtin:room", &relit()).unwrap();
    let ts = TraceScene::new(&scene);
    for v in manifest.views.iter().filter(|v| v.split == "train") {
        let image = load_view(&data, &manifest, v).unwrap();
        let t = image.transfer.as_ref().expect("a training view's transfer");
        let c = project(&v.lighting(&maps).unwrap(), 3);
        let fg: Vec<usize> = (0..image.radiance.len())
            .filter(|&p| image.gbuffer.mask[p] > 0.5)
            .collect();
        assert!(fg.len() > 200, "{} foreground pixels", fg.len());
        let relit = |values: &[f32]| -> Vec3 {
            fg.iter()
                .map(|&p| {
                    (0..9)
                        .map(|k| Vec3::from_slice(&values[(p * 9 + k) * 3..]) * c[k])
                        .sum::<Vec3>()
                })
                .sum()
        };
        let sum = |px: &[Vec3]| fg.iter().map(|&p| px[p]).sum::<Vec3>();
        for (what, got, want) in [
            ("radiance", relit(&t.all), sum(&image.radiance)),
            ("direct", relit(&t.direct), sum(&image.direct)),
        ] {
            let error = ((got - want) / want).abs().max_element();
            assert!(
                error < 0.03,
                "{}: {what} relit {got}, traced {want}",
                v.file
            );
        }
        let settings = RenderSettings {
            spp: 256,
            max_depth: scene.max_depth,
            rr_depth: scene.rr_depth,
            seed: 77,
            filter: PixelFilter::Centre,
            progress: false,
        };
        let sh = ShTransport::precompute(&ts, &v.camera(), 3, &settings);
        let constant: Vec3 = fg.iter().map(|&p| sh.transport[p][0]).sum();
        for k in 0..9 {
            let theirs: Vec3 = fg.iter().map(|&p| sh.transport[p][k]).sum();
            let ours: Vec3 = fg
                .iter()
                .map(|&p| Vec3::from_slice(&t.all[(p * 9 + k) * 3..]))
                .sum();
            let error = ((ours - theirs) / constant).abs().max_element();
            assert!(
                error < 0.02,
                "{}: Y{k} ours {ours}, SH PRT {theirs}",
                v.file
            );
        }
    }
}

/// A pack holds each training pixel's vector as its target has it (f16: within 2⁻¹¹ relative),
/// and a damaged vector is told apart when the pack is opened.
#[test]
fn a_pack_holds_the_vectors_and_tells_when_they_are_damaged() {
    let data = transfer_dataset("transfer-pack");
    let (manifest, hash) = load_manifest_hashed(&data).unwrap();
    let target = PackedTarget::Indirect;
    let open = || PackedDataset::open_or_pack(&data, &manifest, &hash, target, false, |_| {});
    let pack = open().unwrap();
    let mut compared = 0;
    for (i, v) in manifest.views.iter().enumerate() {
        let section = pack.transfer(i).unwrap();
        let image = load_view(&data, &manifest, v).unwrap();
        let fg = (0..image.radiance.len()).filter(|&p| image.gbuffer.mask[p] > 0.5);
        for (r, p) in fg.enumerate() {
            let packed: Vec<f32> = section.vector(r, 9).collect();
            let want: Vec<f32> = match &image.transfer {
                Some(t) => t.pixel(p, true).collect(),
                None => vec![0.0; 27],
            };
            for (a, b) in packed.iter().zip(&want) {
                assert!(
                    (a - b).abs() <= 1e-3 * b.abs() + 1e-7,
                    "{}: {a} {b}",
                    v.file
                );
            }
            compared += 1;
        }
    }
    assert_eq!(compared, pack.records().len());
    assert!(
        !data.join(".packing-transfer.part").exists(),
        "the part file is left"
    );
    let file = PackedDataset::path(&data, target);
    let mut bytes = std::fs::read(&file).unwrap();
    bytes[64 + 40 * pack.records().len() + 7] ^= 0x10;
    drop(pack);
    std::fs::write(&file, bytes).unwrap();
    let err = PackedDataset::open(&file, &manifest, &hash, target)
        .err()
        .unwrap();
    assert!(
        format!("{err:#}").contains("transfer vectors of"),
        "{err:#}"
    );
}

/// The linear design on an SH basis learns the vectors (its loss falls), and what cannot learn
/// them is refused before training: another design, a learned basis, more bands than
/// recorded, a dataset without vectors.
#[test]
fn a_linear_model_learns_transfer_vectors_and_wrong_pairings_are_refused() {
    let data = transfer_dataset("transfer-train");
    let d = data.to_str().unwrap();
    let model = data.parent().unwrap().join("model");
    // On the CPU engine, and on the GPU kernels where an adapter runs them (lavapipe in CI).
    let devices = match common::wgpu_runs() {
        true => &["cpu", "wgpu"][..],
        false => &["cpu"][..],
    };
    for device in devices {
        let model = model.with_extension(device);
        let m = model.to_str().unwrap();
        let mut args = vec!["train", "--data", d, "--out", m, "--device", device];
        args.extend(["--arch", "linear", "--basis", "sh:1", "--direct", "traced"]);
        args.extend(["--targets", "transfer", "--epochs", "12"]);
        args.extend(["--batch-size", "256"]);
        ok(&args);
        let csv = std::fs::read_to_string(model.join("loss.csv")).unwrap();
        // step,epoch,samples,seconds,train_loss,val_loss
        let losses: Vec<f64> = (csv.lines().skip(1))
            .filter_map(|l| l.split(',').nth(4)?.parse().ok())
            .collect();
        let (first, last) = (losses[0], *losses.last().unwrap());
        assert!(
            last < 0.7 * first,
            "{device}: training loss {first} -> {last}"
        );
        let saved = std::fs::read_to_string(model.join("model.json")).unwrap();
        assert!(saved.contains("\"targets\": \"transfer\""), "{saved}");
    }

    let elsewhere = data.parent().unwrap().join("refused");
    let refused = |extra: &[&str], needles: &[&str]| {
        let mut args = vec!["train", "--data", d, "--out", elsewhere.to_str().unwrap()];
        args.extend_from_slice(extra);
        args.extend(["--targets", "transfer", "--epochs", "1"]);
        fails(&args, needles);
    };
    refused(&["--arch", "dsep"], &["--targets transfer", "dsep"]);
    refused(
        &["--arch", "linear", "--basis", "learned:8"],
        &["an SH basis"],
    );
    refused(
        &["--arch", "linear", "--basis", "sh:3"],
        &["sh:2", "fewer bands than the model's sh:3"],
    );
    let plain = data.parent().unwrap().join("plain");
    common::room_dataset(&plain, [2, 1], 16, 2);
    let mut args = vec!["train", "--data", plain.to_str().unwrap()];
    args.extend(["--out", elsewhere.to_str().unwrap(), "--arch", "linear"]);
    args.extend(["--basis", "sh:1", "--targets", "transfer"]);
    fails(&args, &["holds no transfer vectors", "--transfer sh:1"]);
    // On a device the GPU tracer runs on, the recording refuses it; elsewhere the device is
    // refused first, also naming --device cpu.
    let mut args = vec![
        "generate",
        "--scene",
        "builtin:room",
        "--envmaps",
        "builtin",
    ];
    args.extend(["--out", d, "--transfer", "sh:1", "--device", "wgpu"]);
    let why = match devices.len() {
        2 => "CPU tracer only",
        _ => "--device",
    };
    fails(&args, &[why, "--device cpu"]);
    // A flag's value clap refuses (exit 2), with the parser's reason.
    let o = common::nprt(&["generate", "--out", d, "--transfer", "sh:9"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.code() == Some(2) && err.contains("at most sh:8"),
        "{err}"
    );
}
