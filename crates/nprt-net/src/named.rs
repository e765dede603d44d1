//! Parsing of the small named choices (losses, map normalisations, direct light, calibration)
//! from their CLI names.

use anyhow::{bail, Result};

/// `Display` and `FromStr` by name for a choice with `ALL` and `name()`; `$what` names it in
/// the error for an unknown name.
macro_rules! named_choice {
    ($t:ty, $what:literal) => {
        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $t {
            type Err = anyhow::Error;
            fn from_str(s: &str) -> anyhow::Result<Self> {
                $crate::named::by_name(&<$t>::ALL, <$t>::name, s, $what)
            }
        }
    };
}
pub(crate) use named_choice;

/// The one of `all` whose `name` is `s`; otherwise an error naming the `what`, `s` and every
/// accepted name.
pub(crate) fn by_name<T: Copy>(
    all: &[T],
    name: fn(T) -> &'static str,
    s: &str,
    what: &str,
) -> Result<T> {
    if let Some(&t) = all.iter().find(|&&t| name(t) == s) {
        return Ok(t);
    }
    let names: Vec<&str> = all.iter().map(|&t| name(t)).collect();
    let expected = match names.split_last() {
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    };
    bail!("unknown {what} '{s}' (expected {expected})")
}

#[cfg(test)]
mod tests {
    use crate::{Calibration, DirectLight, Loss, MapNorm};

    #[test]
    fn names_parse_and_unknown_ones_list_the_choices() {
        for l in Loss::ALL {
            assert_eq!(l.name().parse::<Loss>().unwrap(), l);
        }
        for n in MapNorm::ALL {
            assert_eq!(n.name().parse::<MapNorm>().unwrap(), n);
        }
        for d in DirectLight::ALL {
            assert_eq!(d.name().parse::<DirectLight>().unwrap(), d);
        }
        for c in Calibration::ALL {
            assert_eq!(c.name().parse::<Calibration>().unwrap(), c);
        }
        let err = "mean".parse::<Calibration>().unwrap_err().to_string();
        assert_eq!(err, "unknown calibration 'mean' (expected none or level)");
        let err = "l2".parse::<Loss>().unwrap_err().to_string();
        assert_eq!(err, "unknown loss 'l2' (expected log-l1 or rel-l2)");
        let err = "max".parse::<MapNorm>().unwrap_err().to_string();
        assert_eq!(
            err,
            "unknown map normalisation 'max' (expected mean or channel)"
        );
    }
}
