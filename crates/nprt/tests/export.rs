//! `nprt export`: the kernels validate and translate, the weights lie where export.json says,
//! and the worked example's WebGPU page, run in headless Chromium (Debian's, on its bundled
//! SwiftShader; scripts/chromium.sh installs it), makes the CPU engine's image. Without
//! Chromium that part skips, unless NPRT_REQUIRE_CHROMIUM is set (scripts/test sets it).
#![cfg(feature = "gpu")]

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use base64::Engine;
use common::{fails, fresh_dir, ok, tiny_room_model};
use serde_json::Value;

const KERNELS: [&str; 5] = [
    "encoder_block",
    "light_project",
    "track_inputs",
    "gemm",
    "combine",
];

#[test]
fn export_writes_kernels_weights_and_a_worked_example_that_webgpu_runs() {
    let dir = fresh_dir("export");
    let model = tiny_room_model(&dir, &["--arch", "dsep", "--encoding", "hash-grid"]);
    let m = model.to_str().unwrap();
    let out = dir.join("export");
    let printed = ok(&[
        "export",
        m,
        "--out",
        out.to_str().unwrap(),
        "--example-res",
        "48x36",
    ]);
    assert!(printed.contains("worked example: serve"), "{printed}");

    for k in KERNELS {
        let glsl = std::fs::read_to_string(out.join(format!("{k}.comp.glsl"))).unwrap();
        assert!(
            glsl.starts_with("#version 430 core") && glsl.contains("layout(std430, binding = 1)"),
            "{k}: {glsl}"
        );
        let hlsl = std::fs::read_to_string(out.join(format!("{k}.hlsl"))).unwrap();
        assert!(
            hlsl.contains("register(b0)") && hlsl.contains("[numthreads("),
            "{k}: {hlsl}"
        );
        assert!(out.join(format!("{k}.wgsl")).is_file());
    }

    // Every tensor where export.json says, back to back, and equal to the model's weights.
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(out.join("export.json")).unwrap()).unwrap();
    let bytes = std::fs::read(out.join("weights.bin")).unwrap();
    let weights: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let mut next = 0;
    for t in manifest["weights"]["tensors"].as_array().unwrap() {
        assert_eq!(t["offset"].as_u64().unwrap() as usize, next, "{t}");
        next += t["shape"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d.as_u64().unwrap() as usize)
            .product::<usize>();
    }
    assert_eq!(next, weights.len());
    let (_, net) = nprt_net::load_model(&model).unwrap();
    assert_eq!(weights.len(), net.total_params());
    let tensor = |name: &str| {
        let t = manifest["weights"]["tensors"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["name"] == name)
            .unwrap();
        let n: usize = t["shape"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d.as_u64().unwrap() as usize)
            .product();
        let o = t["offset"].as_u64().unwrap() as usize;
        weights[o..o + n].to_vec()
    };
    assert_eq!(
        tensor("track1.shading.0.weight"),
        net.tracks[1].shading.layers[0].weight
    );
    assert_eq!(
        tensor("track0.grid"),
        net.tracks[0].grid.as_ref().unwrap().table
    );
    half_precision_kernels_and_weights(&out, &manifest, &tensor);
    assert_eq!(manifest["tracks"][1]["kind"], "specular");
    assert_eq!(manifest["tracks"][0]["width"], 9 + 16);

    page_matches_the_cpu_engine(&out);

    fails(
        &[
            "export",
            m,
            "--out",
            out.to_str().unwrap(),
            "--example-res",
            "300x300",
        ],
        &["at most 65,536 pixels"],
    );
    fails(
        &["export", m, "--out", "/dev/null"],
        &["'/dev/null' is not a folder"],
    );
    let nowhere = dir.join("nowhere");
    fails(
        &[
            "export",
            nowhere.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &["nowhere", "not a model folder"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The linear design exports too: its basis (the functions and the texels' solid angles)
/// instead of an encoder, a code of 3K values, tracks whose shading networks read no code, and
/// a worked example whose page (`light_project`, then the dot products in `combine`) makes
/// the CPU engine's image. The model is the recommended recipe's (`nprt train` without
/// `--arch`): the linear design on sh:2, its direct light traced (left to the engine), its
/// level calibrated (the gain folded into the page's scale).
#[test]
fn the_recipes_linear_model_exports_and_its_page_matches_the_cpu_engine() {
    let dir = fresh_dir("export-linear");
    // ReLU shading networks: with SIREN ones (the default) SwiftShader's sin of their large
    // arguments puts the page 9.1e-5 of the brightest value off the CPU's (6.1e-7 with ReLU),
    // which would hide a wrong layout no better than the bound does.
    let model = tiny_room_model(&dir, &["--activation", "relu"]);
    let out = dir.join("export");
    #[rustfmt::skip]
    let said = ok(&["export", model.to_str().unwrap(), "--out", out.to_str().unwrap(), "--example-res", "48x36"]);
    assert!(
        said.contains(
            "(linear design on sh:2 (relu), direct light traced (left to the engine's renderer"
        ),
        "{said}"
    );
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(out.join("export.json")).unwrap()).unwrap();
    assert_eq!(manifest["model"]["direct"], "traced", "{manifest}");
    let gain = manifest["model"]["output_gain"].as_array().unwrap();
    assert!(
        gain.iter().any(|g| g.as_f64() != Some(1.0)),
        "a calibrated model's gain: {gain:?}"
    );
    assert!(manifest["encoder"].is_null(), "{manifest}");
    assert_eq!(manifest["basis"]["choice"], "sh:2");
    assert_eq!(manifest["code_size"], 27);
    for t in manifest["tracks"].as_array().unwrap() {
        assert_eq!(t["coefficients"], 9, "{t}");
        assert!(t["code_rows"].is_null(), "{t}");
    }
    let (file, net) = nprt_net::load_model(&model).unwrap();
    let nprt_net::LightModel::Basis(basis) = &net.light else {
        panic!("a linear model has a basis")
    };
    let shape = |name: &str| {
        manifest["weights"]["tensors"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["name"] == name)
            .unwrap_or_else(|| panic!("no tensor {name}"))["shape"]
            .clone()
    };
    let w = file.config.encoder_width;
    assert_eq!(shape("basis.functions"), serde_json::json!([9, w * w / 2]));
    assert_eq!(shape("basis.solid_angles"), serde_json::json!([w * w / 2]));
    let example: Value =
        serde_json::from_slice(&std::fs::read(out.join("example/example.json")).unwrap()).unwrap();
    assert_eq!(
        example["light"]["log"], false,
        "a basis reads the map's texels as they are"
    );
    assert_eq!(basis.functions.len(), 9 * w * w / 2);
    page_matches_the_cpu_engine(&out);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A design mixing the light's entries exports too (linear-diffuse: its diffuse track's
/// transfer coefficients dotted with the basis' code at the combine, its specular track's
/// first layer reading that code after ŝ), and its page makes the CPU engine's image.
#[test]
fn a_design_mixing_the_lights_entries_exports_and_its_page_matches_the_cpu_engine() {
    let dir = fresh_dir("export-mixed");
    // ReLU shading networks, as for the linear design above.
    let flags = [
        "--arch",
        "linear-diffuse",
        "--basis",
        "sh:2",
        "--activation",
        "relu",
    ];
    let model = tiny_room_model(&dir, &flags);
    let out = dir.join("export");
    #[rustfmt::skip]
    ok(&["export", model.to_str().unwrap(), "--out", out.to_str().unwrap(), "--example-res", "48x36"]);
    let manifest: Value =
        serde_json::from_slice(&std::fs::read(out.join("export.json")).unwrap()).unwrap();
    assert_eq!(manifest["code_size"], 27);
    let tracks = manifest["tracks"].as_array().unwrap();
    assert_eq!(tracks[0]["coefficients"], 9, "{manifest}");
    assert!(tracks[0]["code_rows"].is_null(), "{manifest}");
    let after_s = nprt_net::TRANSPORT_CODE;
    assert_eq!(
        tracks[1]["code_rows"],
        serde_json::json!([after_s, after_s + 27])
    );
    assert!(tracks[1]["coefficients"].is_null(), "{manifest}");
    page_matches_the_cpu_engine(&out);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The `--precision f16` kernels: WGSL, HLSL where naga writes it (not the tensor-core one),
/// no GLSL (naga writes no f16 GLSL), each gap said in export.json; and every transport layer's
/// weight in `weights_f16.bin` as the f32 weight rounded to f16, rows padded with zeros to a
/// multiple of 16 values, then 16 rows of zeros.
fn half_precision_kernels_and_weights(
    out: &Path,
    manifest: &Value,
    f32_tensor: &dyn Fn(&str) -> Vec<f32>,
) {
    let kernels = manifest["kernels"].as_array().unwrap();
    for (name, has_hlsl) in [
        ("half_rows", true),
        ("half_dense", true),
        ("half_dense_coop", false),
    ] {
        let k = kernels.iter().find(|k| k["name"] == name).unwrap();
        assert_eq!(k["precision"], "f16", "{k}");
        assert!(out.join(format!("{name}.wgsl")).is_file());
        assert!(k["glsl"].is_null() && k["glsl_missing"].is_string(), "{k}");
        let hlsl = out.join(format!("{name}.hlsl"));
        assert_eq!(hlsl.is_file(), has_hlsl, "{name}");
        assert_eq!(k["hlsl"].is_null(), !has_hlsl, "{k}");
        if has_hlsl {
            assert!(std::fs::read_to_string(hlsl).unwrap().contains("half"));
        }
    }
    let bytes = std::fs::read(out.join("weights_f16.bin")).unwrap();
    let halves: Vec<u16> = bytes
        .chunks_exact(2)
        .map(|b| u16::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let tensors = manifest["weights_f16"]["tensors"].as_array().unwrap();
    // Two tracks of D/S: a transfer and a shading network each.
    assert!(tensors.len() >= 8, "{tensors:?}");
    let mut next = 0;
    for t in tensors {
        let dims = |key: &str| -> Vec<usize> {
            t[key]
                .as_array()
                .unwrap()
                .iter()
                .map(|d| d.as_u64().unwrap() as usize)
                .collect()
        };
        let (shape, weight_shape) = (dims("shape"), dims("weight_shape"));
        let (&[rows, n_pad], &[d_in, d_out]) = (&shape[..], &weight_shape[..]) else {
            panic!("{t}")
        };
        assert_eq!(
            (rows, n_pad % 16, n_pad - d_out < 16),
            (d_in + 16, 0, true),
            "{t}"
        );
        assert_eq!(t["offset"].as_u64().unwrap() as usize, next, "{t}");
        let weight = f32_tensor(t["name"].as_str().unwrap());
        for i in 0..rows {
            for j in 0..n_pad {
                let got = halves[next + i * n_pad + j];
                let want = match i < d_in && j < d_out {
                    true => half::f16::from_f32(weight[i * d_out + j]).to_bits(),
                    false => 0,
                };
                assert_eq!(got, want, "{t}: ({i}, {j})");
            }
        }
        next += rows * n_pad;
    }
    assert_eq!(next, halves.len());
}

/// Serves `export` from localhost, opens its example page in headless Chromium with WebGPU on
/// SwiftShader, and checks what the page reports: every foreground pixel within 1e-4 of the
/// brightest value of the CPU engine's image (SwiftShader: ~1e-5). The page's canvas is kept
/// as `example/page.png` for a person to look at.
fn page_matches_the_cpu_engine(export: &Path) {
    let Some(chromium) = chromium() else { return };
    let (port, results) = serve(export.to_path_buf());
    let profile = export.join("chromium-profile");
    let mut browser = std::process::Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--enable-unsafe-webgpu",
            "--enable-features=Vulkan",
            "--use-vulkan=swiftshader",
            "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader",
            "--ignore-gpu-blocklist",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("http://127.0.0.1:{port}/example/?report"))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .process_group(0)
        .spawn()
        .expect("start chromium");
    let result = results.recv_timeout(Duration::from_secs(240));
    end_process_group(&mut browser);
    let result: Value =
        serde_json::from_str(&result.expect("the page reports within 4 minutes")).unwrap();
    assert!(result["error"].is_f64(), "the page failed: {result}");
    let error = result["error"].as_f64().unwrap();
    let example: Value =
        serde_json::from_slice(&std::fs::read(export.join("example/example.json")).unwrap())
            .unwrap();
    assert_eq!(
        (example["width"].as_u64(), example["height"].as_u64()),
        (Some(48), Some(36))
    );
    assert!(result["rows"].as_u64().unwrap() > 48 * 36 / 2, "{result}");
    assert!(
        error < 1e-4,
        "the page's image is off by {error} of the brightest value"
    );
    let png = result["image"]
        .as_str()
        .unwrap()
        .strip_prefix("data:image/png;base64,")
        .unwrap();
    let png = base64::engine::general_purpose::STANDARD
        .decode(png)
        .unwrap();
    std::fs::write(export.join("example/page.png"), png).unwrap();
    let page = image::open(export.join("example/page.png"))
        .unwrap()
        .to_rgb8();
    assert_eq!(page.dimensions(), (48, 36));
    assert!(
        page.pixels().any(|p| p.0.iter().any(|&c| c > 8)),
        "the canvas shows the room"
    );
    eprintln!("page: {result:.80}", result = result.to_string());
}

/// Kills a process started in its own group and every process of that group, and waits until
/// none is left: Chromium's GPU and renderer processes outlive its main one and go on writing
/// its profile, which would race the test's removal of the folder.
fn end_process_group(leader: &mut std::process::Child) {
    let group = leader.id() as libc::pid_t;
    // SAFETY: killpg only sends a signal; the group is the one this test created.
    unsafe { libc::killpg(group, libc::SIGKILL) };
    leader.wait().ok();
    let deadline = Instant::now() + Duration::from_secs(30);
    // SAFETY: signal 0 only asks whether any process of the group is left.
    while unsafe { libc::killpg(group, 0) } == 0 && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Debian's Chromium, or None (the page test skipped) where it is not installed and not required.
fn chromium() -> Option<PathBuf> {
    let found = std::env::var_os("PATH")
        .into_iter()
        .flat_map(|p| std::env::split_paths(&p).collect::<Vec<_>>())
        .map(|d| d.join("chromium"))
        .find(|p| p.is_file());
    if found.is_none() {
        assert!(
            std::env::var_os("NPRT_REQUIRE_CHROMIUM").is_none(),
            "NPRT_REQUIRE_CHROMIUM is set but chromium is not on PATH (scripts/chromium.sh installs it)"
        );
        eprintln!("skipped the WebGPU page: chromium is not installed (scripts/chromium.sh)");
    }
    found
}

/// A static file server on a free localhost port for `root`, which passes the body of every
/// POST to /result to the receiver.
fn serve(root: PathBuf) -> (u16, mpsc::Receiver<String>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let (root, tx) = (root.clone(), tx.clone());
            std::thread::spawn(move || answer(stream, &root, &tx));
        }
    });
    (port, rx)
}

fn answer(stream: TcpStream, root: &Path, results: &mpsc::Sender<String>) {
    let deadline = Instant::now() + Duration::from_secs(30);
    stream.set_read_timeout(Some(Duration::from_secs(30))).ok();
    let mut reader = BufReader::new(stream.try_clone().unwrap());
    let mut line = String::new();
    if reader.read_line(&mut line).is_err() || Instant::now() > deadline {
        return;
    }
    let mut parts = line.split_whitespace();
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or("/"));
    let mut length = 0;
    loop {
        let mut header = String::new();
        if reader.read_line(&mut header).unwrap_or(0) == 0 || header.trim().is_empty() {
            break;
        }
        if let Some((name, value)) = header.split_once(':') {
            if name.eq_ignore_ascii_case("content-length") {
                length = value.trim().parse().unwrap_or(0);
            }
        }
    }
    let mut stream = stream;
    if method == "POST" {
        let mut body = vec![0; length];
        reader.read_exact(&mut body).ok();
        results
            .send(String::from_utf8_lossy(&body).into_owned())
            .ok();
        stream
            .write_all(b"HTTP/1.1 200 OK\r\nContent-Length: 0\r\nConnection: close\r\n\r\n")
            .ok();
        return;
    }
    let path = target
        .split('?')
        .next()
        .unwrap_or("/")
        .trim_start_matches('/');
    let path = if path.is_empty() || path.ends_with('/') {
        format!("{path}index.html")
    } else {
        path.to_string()
    };
    let file = root.join(&path);
    let (status, body) = match std::fs::read(&file) {
        Ok(b) if !path.contains("..") => ("200 OK", b),
        _ => ("404 Not Found", Vec::new()),
    };
    let kind = match file.extension().and_then(|e| e.to_str()) {
        Some("html") => "text/html",
        Some("js") => "text/javascript",
        Some("json") => "application/json",
        _ => "application/octet-stream",
    };
    let head = format!("HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n", body.len());
    stream.write_all(head.as_bytes()).ok();
    stream.write_all(&body).ok();
}
