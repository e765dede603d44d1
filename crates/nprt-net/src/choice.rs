//! The small named choices (designs, activations, losses, devices, …): each enum's names are
//! stated once, in its [`named_choice!`] invocation, which gives it `ALL`, `name()`, `Display`,
//! `FromStr` (an unknown name lists the accepted ones) and serde by the same names, so the
//! command line, model.json and messages cannot disagree.

/// `named_choice!(Type, "what it is", { Variant => "name", … })`.
macro_rules! named_choice {
    ($t:ident, $what:literal, { $($variant:ident => $name:literal),+ $(,)? }) => {
        impl $t {
            pub const ALL: [$t; <[&str]>::len(&[$($name),+])] = [$($t::$variant),+];

            pub fn name(self) -> &'static str {
                match self {
                    $($t::$variant => $name),+
                }
            }
        }

        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $t {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                $crate::choice::by_name(&<$t>::ALL, <$t>::name, s, $what)
            }
        }

        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }

        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let s = <String as serde::Deserialize>::deserialize(d)?;
                s.parse().map_err(serde::de::Error::custom)
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
) -> Result<T, String> {
    if let Some(&t) = all.iter().find(|&&t| name(t) == s) {
        return Ok(t);
    }
    let names: Vec<&str> = all.iter().map(|&t| name(t)).collect();
    let expected = match names.split_last() {
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    };
    Err(format!("unknown {what} '{s}' (expected {expected})"))
}

#[cfg(test)]
mod tests {
    use crate::PositionEncoding;
    use crate::{Activation, Calibration, Compute, Design, DirectLight, Loss, LrSchedule, MapNorm};

    /// Every choice's name parses back and round-trips through serde (model.json).
    fn round_trips<T>(all: &[T])
    where
        T: Copy + PartialEq + std::fmt::Debug + std::fmt::Display + std::str::FromStr,
        T: serde::Serialize + serde::de::DeserializeOwned,
        <T as std::str::FromStr>::Err: std::fmt::Debug,
    {
        for &c in all {
            assert_eq!(c.to_string().parse::<T>().unwrap(), c);
            let json = serde_json::to_string(&c).unwrap();
            assert_eq!(json, format!("\"{c}\""));
            assert_eq!(serde_json::from_str::<T>(&json).unwrap(), c);
        }
    }

    #[test]
    fn names_parse_and_unknown_ones_list_the_choices() {
        round_trips(&Loss::ALL);
        round_trips(&MapNorm::ALL);
        round_trips(&DirectLight::ALL);
        round_trips(&Calibration::ALL);
        round_trips(&PositionEncoding::ALL);
        round_trips(&Design::ALL);
        round_trips(&Activation::ALL);
        round_trips(&LrSchedule::ALL);
        round_trips(&Compute::ALL);
        let err = "mean".parse::<Calibration>().unwrap_err().to_string();
        assert_eq!(err, "unknown calibration 'mean' (expected none or level)");
        let err = "l2".parse::<Loss>().unwrap_err().to_string();
        assert_eq!(err, "unknown loss 'l2' (expected log-l1 or rel-l2)");
        let err = "max".parse::<MapNorm>().unwrap_err().to_string();
        assert_eq!(
            err,
            "unknown map normalisation 'max' (expected mean or channel)"
        );
        // A list of three or more: commas, then "or" (the designs' names, whatever they are).
        let err = serde_json::from_str::<Design>("\"mlp\"")
            .unwrap_err()
            .to_string();
        let names = Design::ALL.map(Design::name);
        let (last, rest) = names.split_last().unwrap();
        let want = format!(
            "unknown design 'mlp' (expected {} or {last})",
            rest.join(", ")
        );
        assert!(rest.len() >= 2 && err.contains(&want), "{err}");
    }
}
