//! An error as nprt says it, to a terminal or to Python: the message and its causes, each once;
//! and a number as an error says it.

/// `e` and its causes joined by colons, each said once: some libraries' messages (exr's,
/// image's) and some of nprt's own already end with their cause's, which `{:#}` would repeat
/// ("cannot read 'x.exr': cannot read 'x.exr': …").
pub fn describe_error(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain().map(|c| c.to_string()) {
        if text.is_empty() {
            text = cause;
        } else if !text.ends_with(&cause) {
            text = format!("{text}: {cause}");
        }
    }
    text
}

/// `v` as written plainly where that is short, else in scientific notation: a refused 1e-300
/// is said as such, not as 300 digits.
pub fn short_number<T>(v: T) -> String
where
    T: Copy + Into<f64> + std::fmt::Display + std::fmt::LowerExp,
{
    let x: f64 = v.into();
    match x == 0.0 || (1e-4..1e7).contains(&x.abs()) || !x.is_finite() {
        true => format!("{v}"),
        false => format!("{v:e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_said_plainly_or_in_scientific_notation() {
        let said = [0.0, -1.0, 0.5, 1e30, 1e-300, f64::NAN, 123456.0].map(short_number);
        assert_eq!(said, ["0", "-1", "0.5", "1e30", "1e-300", "NaN", "123456"]);
        assert_eq!(short_number(1e30f32), "1e30");
    }

    #[test]
    fn a_cause_its_message_already_ends_with_is_said_once() {
        let e = anyhow::anyhow!("no such file")
            .context("cannot read 'a.exr': no such file")
            .context("map 'a.exr'");
        assert_eq!(
            describe_error(&e),
            "map 'a.exr': cannot read 'a.exr': no such file"
        );
        assert_eq!(
            format!("{e:#}"),
            "map 'a.exr': cannot read 'a.exr': no such file: no such file"
        );
    }
}
