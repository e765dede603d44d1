//! Text drawn over the frame (timings, keys) in an 8×8 bitmap font, light on a dark shadow so
//! that it reads over any image: into an RGBA8 image laid over the frame, opaque where it
//! draws.

use font8x8::UnicodeFonts;

/// Draws `lines` from the top-left corner of an RGBA8 image `width` pixels wide, at `scale`
/// pixels per font pixel, each wrapped at spaces to the image's width.
pub fn draw_lines(rgba: &mut [u8], width: usize, lines: &[String], scale: usize) {
    let height = rgba.len() / 4 / width;
    let columns = (width / scale).saturating_sub(8) / 8;
    let lines: Vec<String> = lines.iter().flat_map(|l| wrap(l, columns.max(1))).collect();
    let mut put = |x: usize, y: usize, v: u8| {
        if x < width && y < height {
            let p = 4 * (y * width + x);
            rgba[p..p + 4].copy_from_slice(&[v, v, v, 255]);
        }
    };
    for (row, line) in lines.iter().enumerate() {
        for (col, c) in line.chars().enumerate() {
            let glyph = font8x8::BASIC_FONTS
                .get(c)
                .or_else(|| font8x8::LATIN_FONTS.get(c))
                .unwrap_or([0; 8]);
            for (gy, bits) in glyph.iter().enumerate() {
                for gx in 0..8 {
                    if bits >> gx & 1 == 0 {
                        continue;
                    }
                    let (x0, y0) = ((4 + col * 8 + gx) * scale, (4 + row * 10 + gy) * scale);
                    for k in 0..scale * scale {
                        put(x0 + k % scale + scale, y0 + k / scale + scale, 0);
                        put(x0 + k % scale, y0 + k / scale, 255);
                    }
                }
            }
        }
    }
}

/// `line` cut into pieces of at most `columns` characters, at spaces where it can be.
fn wrap(line: &str, columns: usize) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest: Vec<char> = line.chars().collect();
    while rest.len() > columns {
        let cut = rest[..=columns]
            .iter()
            .rposition(|&c| c == ' ')
            .filter(|&i| i > 0)
            .unwrap_or(columns);
        out.push(rest[..cut].iter().collect());
        rest.drain(..cut);
        while rest.first() == Some(&' ') {
            rest.remove(0);
        }
    }
    out.push(rest.into_iter().collect());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_lines_wrap_at_spaces_and_text_lands_in_the_corner() {
        assert_eq!(
            wrap("networks on the GPU kernels", 12),
            ["networks on", "the GPU", "kernels"]
        );
        assert_eq!(wrap("abcdefghij", 4), ["abcd", "efgh", "ij"]);
        let mut rgba = vec![100; 4 * 64 * 32];
        draw_lines(&mut rgba, 64, &["I".into()], 1);
        let lit: Vec<usize> = (0..64 * 32).filter(|&p| rgba[4 * p] == 255).collect();
        assert!(
            !lit.is_empty() && lit.iter().all(|&p| p % 64 < 16 && p / 64 < 16),
            "{lit:?}"
        );
    }
}
