//! Mitsuba 0.x files read as Mitsuba 3 upgrades them.

use std::borrow::Cow;

/// Mitsuba 3's upgrade of a 0.x property name: `toWorld` → `to_world`, `intIOR` → `int_ior`
/// (an upper-case letter after a lower-case one starts a word, and the capitals that follow
/// belong to it).
pub(super) fn snake_case(name: &str) -> Cow<'_, str> {
    let b = name.as_bytes();
    if !b
        .windows(2)
        .any(|w| w[0].is_ascii_lowercase() && w[1].is_ascii_uppercase())
    {
        return Cow::Borrowed(name);
    }
    let mut out = String::with_capacity(name.len() + 4);
    let mut i = 0;
    while i < b.len() {
        if i > 0 && b[i - 1].is_ascii_lowercase() && b[i].is_ascii_uppercase() {
            out.push('_');
            while i < b.len() && b[i].is_ascii_uppercase() {
                out.push(b[i].to_ascii_lowercase() as char);
                i += 1;
            }
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    Cow::Owned(out)
}
