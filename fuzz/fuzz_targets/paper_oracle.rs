//! What the `nprt paper` targets hold every accepted file to: its report carries no number
//! that is not one (the words NaN or inf), unless the input itself spells one (a method's name
//! is free text). Included by each paper target.

/// Whether `md`, made from `input`, shows a non-finite number.
#[allow(dead_code)]
pub fn shows_non_finite(md: &str, input: &[u8]) -> bool {
    let spelled = String::from_utf8_lossy(input).to_lowercase();
    if spelled.contains("nan") || spelled.contains("inf") {
        return false;
    }
    md.split(|c: char| !c.is_alphanumeric())
        .any(|w| w.eq_ignore_ascii_case("nan") || w.eq_ignore_ascii_case("inf"))
}

/// The first `u32`-length-prefixed part of `data`, and the rest.
#[allow(dead_code)]
pub fn split_pair(data: &[u8]) -> Option<(&[u8], &[u8])> {
    let (len, rest) = data.split_first_chunk::<4>()?;
    let len = (u32::from_le_bytes(*len) as usize).min(rest.len());
    Some(rest.split_at(len))
}
