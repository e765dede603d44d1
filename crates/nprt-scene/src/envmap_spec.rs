//! Which environment map a command-line spec names: a file, or a procedural built-in.

use anyhow::{bail, Context, Result};

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
        .map(|s| {
            s.parse::<f32>()
                .with_context(|| format!("environment map '{spec}': '{s}' is not a number"))
        })
        .collect::<Result<_>>()?;
    match kind {
        "sky" => {
            let d = SkyParams::default();
            let get = |i: usize, v: f32| nums.get(i).copied().unwrap_or(v);
            sky(SkyParams { elevation: get(0, d.elevation), azimuth: get(1, d.azimuth), turbidity: get(2, d.turbidity), width: d.width })
        }
        "indoor" => indoor(nums.first().copied().unwrap_or(0.0) as u64, 256),
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
    }
}
