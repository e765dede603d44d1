//! Which environment map a command-line spec names: a file, or a procedural built-in.

use anyhow::{bail, Result};

use crate::envmap::EnvMap;
use crate::procedural::{indoor, sky, SkyParams};

/// Opens an environment map from a file path or a built-in spec:
/// `builtin:sky[:ELEVATION[:AZIMUTH[:TURBIDITY]]]` or `builtin:indoor[:SEED]`.
pub fn open_envmap(spec: &str) -> Result<EnvMap> {
    let Some(rest) = spec.strip_prefix("builtin:") else {
        return EnvMap::load(std::path::Path::new(spec), 1.0);
    };
    let mut parts = rest.split(':');
    let kind = parts.next().unwrap_or("");
    let nums: Vec<f32> = parts
        .map(|s| match s.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => bail!("environment map '{spec}': '{s}' is not a finite number"),
        })
        .collect::<Result<_>>()?;
    let most = if kind == "sky" { 3 } else { 1 };
    if nums.len() > most {
        bail!(
            "environment map '{spec}': builtin:{kind} takes at most {most} numbers, got {}",
            nums.len()
        );
    }
    match kind {
        "sky" => {
            let d = SkyParams::default();
            let get = |i: usize, v: f32| nums.get(i).copied().unwrap_or(v);
            sky(SkyParams { elevation: get(0, d.elevation), azimuth: get(1, d.azimuth), turbidity: get(2, d.turbidity), width: d.width })
        }
        "indoor" => {
            // A seed is a whole number: -1 or 2.5 would silently be another map's.
            let seed = nums.first().copied().unwrap_or(0.0);
            if seed < 0.0 || seed.fract() != 0.0 || seed >= 2f32.powi(24) {
                bail!("environment map '{spec}': the seed must be a whole number from 0 to 16777215, got {seed}");
            }
            indoor(seed as u64, 256)
        }
        _ => bail!("unknown built-in environment map '{spec}' (expected builtin:sky[:ELEV[:AZIM[:TURB]]] or builtin:indoor[:SEED])"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_fail_clearly() {
        assert!(open_envmap("builtin:sky:20:45:4").is_ok());
        let err = open_envmap("builtin:moon").unwrap_err().to_string();
        assert!(err.contains("builtin:moon"), "{err}");
        for bad in [
            "builtin:indoor:-1",
            "builtin:indoor:2.5",
            "builtin:indoor:1e30",
            "builtin:indoor:1:2",
            "builtin:sky:nan",
            "builtin:sky:20:inf",
            "builtin:sky:1:2:3:4",
        ] {
            let err = open_envmap(bad).unwrap_err().to_string();
            assert!(err.contains(bad), "{bad}: {err}");
        }
        assert!(open_envmap("builtin:indoor:16777215").is_ok());
    }
}
