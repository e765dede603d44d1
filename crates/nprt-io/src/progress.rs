//! The one progress bar style: what is counted, how far, elapsed time and ETA.

use indicatif::{ProgressBar, ProgressStyle};

/// A bar over `len` `unit`s of `what` (e.g. "generating", "views"); hidden unless `show`.
/// Callers put live figures (a loss, a rate) in its message.
pub fn progress_bar(show: bool, len: u64, what: &str, unit: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    let template = format!(
        "{{spinner}} {what} [{{bar:30}}] {{pos}}/{{len}} {unit} {{msg}} ({{elapsed}} elapsed, ETA {{eta}})"
    );
    // The template is a constant shape; only `what` and `unit` vary, and braces in them would
    // only be printed literally if escaped, so fall back to the default style rather than fail.
    if let Ok(style) = ProgressStyle::with_template(&template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}
