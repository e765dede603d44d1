//! A key a script presses in `nprt view` (`--keys SECONDS:KEY,…`), its names stated once: the
//! command line parses them into a [`ScriptedKey`] (in every build, the viewer's or not), and
//! the viewer presses it.

use std::str::FromStr;

/// A key `--keys` names: one character, or space, tab, escape (esc) or f12.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScriptedKey {
    Space,
    Tab,
    Escape,
    F12,
    Character(char),
}

impl FromStr for ScriptedKey {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s {
            "space" => ScriptedKey::Space,
            "tab" => ScriptedKey::Tab,
            "escape" | "esc" => ScriptedKey::Escape,
            "f12" => ScriptedKey::F12,
            _ => {
                let mut chars = s.chars();
                match (chars.next(), chars.next()) {
                    (Some(c), None) => ScriptedKey::Character(c),
                    _ => {
                        return Err(format!(
                            "'{s}' is not a key: one character, or space, tab, escape or f12"
                        ))
                    }
                }
            }
        })
    }
}
