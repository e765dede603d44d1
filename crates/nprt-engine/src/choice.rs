//! The small named choices (designs, activations, losses, devices, …): each enum's names are
//! stated once, in its [`named_choice!`] invocation, which gives it `ALL`, `name()`, `Display`,
//! `FromStr` (an unknown name lists the accepted ones) and serde by the same names, so the
//! command line, model.json and messages cannot disagree.

/// `named_choice!(Type, "what it is", { Variant => "name", … })` (the caller depends on
/// serde).
#[macro_export]
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
pub use crate::named_choice;

/// The one of `all` whose `name` is `s`; otherwise an error naming the `what`, `s` and every
/// accepted name.
pub fn by_name<T: Copy>(
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
