//! Flags and value parsers shared by several subcommands.

use std::fmt;
use std::str::FromStr;

use anyhow::{bail, Result};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use nprt_net::training::snapshot::Snapshot;
use nprt_net::{Compute, Design, Engine, LrSchedule, RunLength};

/// `--arch`'s parser: the designs' names from `Design::ALL` as clap's possible values, which
/// `--help` lists, so that no command states the list of designs by hand.
pub fn design_names() -> impl TypedValueParser<Value = Design> {
    PossibleValuesParser::new(Design::ALL.map(Design::name))
        .map(|name| name.parse().expect("a name from Design::ALL"))
}

/// `--device`, shared by every command that runs the networks.
#[derive(clap::Args, Clone, Copy)]
pub struct DeviceArg {
    /// Where the networks run: cpu (the CPU engine), gpu (nprt's own kernels on the best GPU
    /// adapter wgpu finds, Vulkan, Metal or DX12, a discrete one first; an error if there is
    /// none or this nprt was built without the `gpu` feature), wgpu (the same kernels on any
    /// adapter, software ones such as Mesa's lavapipe included: how the GPU code is tested
    /// without a GPU) or auto (gpu when a hardware adapter is found, else the CPU, saying why).
    /// A model folder is the same whichever trained it.
    #[arg(long = "device", default_value_t = Compute::Auto)]
    pub compute: Compute,
}

impl DeviceArg {
    pub fn engine(self) -> Result<Engine> {
        self.compute.engine()
    }
}

/// How long a training run lasts and how its learning rate moves, shared by both trainings.
#[derive(clap::Args, Clone, Copy)]
pub struct RunArgs {
    /// Passes over the training data, 1 to 100,000 (the paper: 500) [default: 20, or as many
    /// as fit with --minutes].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub epochs: Option<u32>,
    /// Wall-clock budget: stop when the run's training time reaches this many minutes (or
    /// after --epochs if given, whichever comes first). The same command continues a stopped
    /// run up to the budget.
    #[arg(long, value_parser = finite_f64)]
    pub minutes: Option<f64>,
    /// Learning-rate schedule: paper (--lr throughout, as the paper) or cosine (warm-up over
    /// the first 2% of the run, then a cosine decay to 5% of --lr at its end: the last epoch,
    /// or the end of --minutes). A cosine run keeps its length: it cannot be lengthened later.
    /// [default: cosine for train, paper for train-deep-shading]
    #[arg(long)]
    pub schedule: Option<LrSchedule>,
}

impl From<RunArgs> for RunLength {
    fn from(a: RunArgs) -> Self {
        RunLength {
            epochs: a.epochs.map(|e| e as usize),
            minutes: a.minutes,
            lr_schedule: a.schedule,
        }
    }
}

/// A frame size, `N` (square) or `WxH`, as flags take it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolution(pub [u32; 2]);

impl FromStr for Resolution {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let parse = |t: &str| {
            t.parse::<u32>()
                .ok()
                .filter(|&v| v > 0)
                .ok_or(format!("'{s}' is not N or WxH with positive sizes"))
        };
        match s.split_once('x') {
            Some((w, h)) => Ok(Resolution([parse(w)?, parse(h)?])),
            None => parse(s).map(|n| Resolution([n, n])),
        }
    }
}

impl fmt::Display for Resolution {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            [w, h] if w == h => write!(f, "{w}"),
            [w, h] => write!(f, "{w}x{h}"),
        }
    }
}

/// `K/N`: shard K of N.
pub fn parse_shard(s: &str) -> Result<(u64, u64), String> {
    let bad = || format!("'{s}' is not K/N with 0 ≤ K < N");
    let (k, n) = s.split_once('/').ok_or_else(bad)?;
    let (k, n) = (
        k.parse::<u64>().map_err(|_| bad())?,
        n.parse::<u64>().map_err(|_| bad())?,
    );
    if n == 0 || k >= n {
        return Err(bad());
    }
    Ok((k, n))
}

/// A `--snapshots` list (a type of its own: clap takes an `Option<Vec<_>>` for a repeated flag).
#[derive(Clone)]
pub struct Snapshots(pub Vec<Snapshot>);

pub fn parse_snapshots(s: &str) -> Result<Snapshots, String> {
    Snapshot::parse_list(s).map(Snapshots)
}

/// A finite number: clap's own parsers take "nan" and "inf", which no flag means.
pub fn finite_f32(s: &str) -> Result<f32, String> {
    finite(s)
}

/// [`finite_f32`] in double precision.
pub fn finite_f64(s: &str) -> Result<f64, String> {
    finite(s)
}

fn finite<T: FromStr + Into<f64> + Copy>(s: &str) -> Result<T, String> {
    match s.trim().parse::<T>() {
        Ok(v) if v.into().is_finite() => Ok(v),
        Ok(_) => Err(format!("'{s}' is not a finite number")),
        Err(_) => Err(format!("'{s}' is not a number")),
    }
}

/// `x,y,z`, each finite.
pub fn parse_vec3(s: &str) -> Result<glam::Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(finite)
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{s}' is not x,y,z (three finite numbers)"))?;
    match v.as_slice() {
        [x, y, z] => Ok(glam::Vec3::new(*x, *y, *z)),
        _ => Err(format!("'{s}' is not x,y,z")),
    }
}

/// `NAME=VALUE` pairs of `--set`.
pub fn parse_set(items: &[String]) -> Result<Vec<(String, String)>> {
    items
        .iter()
        .map(|s| match s.split_once('=') {
            Some((k, v)) if !k.is_empty() => Ok((k.to_string(), v.to_string())),
            _ => bail!("--set expects NAME=VALUE, got '{s}'"),
        })
        .collect()
}

/// Prints what a library owes the user before its work starts.
pub fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}
