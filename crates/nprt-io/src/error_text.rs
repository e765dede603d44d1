//! An error as nprt says it, to a terminal or to Python: the message and its causes, each once.

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

#[cfg(test)]
mod tests {
    use super::*;

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
