//! The PyTorch peer of the training benchmark: bench/train_pytorch.py (the same layers, batch
//! and loss), embedded in the binary so that `nprt bench train --python PY` runs wherever nprt
//! is installed, not only inside the source tree.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};

use crate::network::activation::Activation;
use crate::network::design::Design;

const SCRIPT: &str = include_str!("../../../../bench/train_pytorch.py");

/// What the peer is asked to measure (as `nprt bench train` measures itself).
pub struct PeerRun<'a> {
    pub python: &'a Path,
    pub design: Design,
    pub activation: Option<Activation>,
    pub batch_size: usize,
    pub views: usize,
    pub steps: usize,
    pub warmup: usize,
    pub threads: usize,
    /// PyTorch's name of the device ("cpu", "cuda").
    pub torch_device: &'a str,
    pub variant: PeerVariant,
}

/// How PyTorch runs the step: eager or compiled (torch.compile), in f32 or under bf16
/// autocast. Named "eager-f32", "compile-bf16" and so on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PeerVariant {
    pub compile: bool,
    pub bf16: bool,
}

impl PeerVariant {
    pub const ALL: [PeerVariant; 4] = [
        PeerVariant {
            compile: false,
            bf16: false,
        },
        PeerVariant {
            compile: false,
            bf16: true,
        },
        PeerVariant {
            compile: true,
            bf16: false,
        },
        PeerVariant {
            compile: true,
            bf16: true,
        },
    ];

    pub fn name(self) -> String {
        format!(
            "{}-{}",
            if self.compile { "compile" } else { "eager" },
            if self.bf16 { "bf16" } else { "f32" }
        )
    }
}

impl std::str::FromStr for PeerVariant {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| {
                format!("unknown PyTorch variant '{s}': eager-f32, eager-bf16, compile-f32 or compile-bf16")
            })
    }
}

/// The embedded script written out for one process's runs, removed when dropped.
pub struct PeerScript(PathBuf);

impl PeerScript {
    pub fn write() -> Result<Self> {
        let path =
            std::env::temp_dir().join(format!("nprt-train-pytorch-{}.py", std::process::id()));
        std::fs::write(&path, SCRIPT)
            .with_context(|| format!("cannot write the PyTorch peer to '{}'", path.display()))?;
        Ok(PeerScript(path))
    }

    /// Runs the peer once and returns its samples/s.
    pub fn run(&self, r: &PeerRun) -> Result<f64> {
        let mut cmd = Command::new(r.python);
        cmd.arg(&self.0)
            .args(["--designs", r.design.name()])
            .args(["--batch-size", &r.batch_size.to_string()])
            .args(["--views", &r.views.to_string()])
            .args(["--steps", &r.steps.to_string()])
            .args(["--warmup", &r.warmup.to_string()])
            .args(["--threads", &r.threads.to_string()])
            .args(["--device", r.torch_device]);
        if r.variant.compile {
            cmd.arg("--compile");
        }
        if r.variant.bf16 {
            cmd.args(["--autocast", "bf16"]);
        }
        if let Some(act) = r.activation {
            cmd.args(["--activation", act.name()]);
        }
        let out = cmd
            .output()
            .with_context(|| format!("cannot run '{}'", r.python.display()))?;
        if !out.status.success() {
            bail!(
                "PyTorch peer failed: {}",
                String::from_utf8_lossy(&out.stderr)
                    .lines()
                    .last()
                    .unwrap_or("")
            );
        }
        let stdout = String::from_utf8_lossy(&out.stdout);
        let line = stdout
            .lines()
            .last()
            .context("PyTorch peer printed nothing")?;
        let v: serde_json::Value =
            serde_json::from_str(line).context("PyTorch peer printed non-JSON")?;
        v["samples_per_s"]
            .as_f64()
            .context("PyTorch peer printed no samples_per_s")
    }
}

impl Drop for PeerScript {
    fn drop(&mut self) {
        std::fs::remove_file(&self.0).ok();
    }
}
