//! report.md as one self-contained HTML page.

use std::path::Path;

use anyhow::{Context, Result};
use base64::Engine;

/// Renders a report's Markdown as one HTML page titled `title` (pulldown-cmark, with tables)
/// with every image (a path relative to `dir`) embedded as a data URI, so the page can be
/// mailed or moved alone.
pub fn markdown_to_html(md: &str, dir: &Path, title: &str) -> Result<String> {
    use pulldown_cmark::{Event, Options, Parser, Tag};
    let mut events = Vec::new();
    for event in Parser::new_ext(md, Options::ENABLE_TABLES) {
        events.push(match event {
            Event::Start(Tag::Image {
                link_type,
                dest_url,
                title,
                id,
            }) => {
                let file = dir.join(dest_url.as_ref());
                let bytes = std::fs::read(&file)
                    .with_context(|| format!("cannot read report image '{}'", file.display()))?;
                let b64 = base64::engine::general_purpose::STANDARD.encode(bytes);
                Event::Start(Tag::Image {
                    link_type,
                    dest_url: format!("data:image/png;base64,{b64}").into(),
                    title,
                    id,
                })
            }
            other => other,
        });
    }
    let mut html = format!(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{title}</title><style>{STYLE}</style></head><body>\n"
    );
    pulldown_cmark::html::push_html(&mut html, events.into_iter());
    html += "</body></html>\n";
    Ok(html)
}

/// The reports' page style: readable tables, pixel-exact thumbnails.
const STYLE: &str = "body{font-family:sans-serif;max-width:1400px;margin:2em auto;padding:0 1em}\
    table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:4px 8px;text-align:right}\
    td:first-child,th:first-child{text-align:left}img{image-rendering:pixelated;max-width:100%}\
    td img{width:192px}";
