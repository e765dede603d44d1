//! Text drawn over the frame (timings, keys) in an 8×8 bitmap font, light on a dark shadow so
//! that it reads over any image: into an RGBA8 image laid over the frame, opaque where it
//! draws.

use font8x8::UnicodeFonts;

/// Draws `lines` from the top-left corner of an RGBA8 image `width` pixels wide, at `scale`
/// pixels per font pixel, each wrapped at spaces to the first `text_width` pixels; returns
/// the first row below the text.
pub fn draw_lines(
    rgba: &mut [u8],
    width: usize,
    text_width: usize,
    lines: &[String],
    scale: usize,
) -> usize {
    let height = rgba.len() / 4 / width;
    let columns = (text_width.min(width) / scale).saturating_sub(8) / 8;
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
    (6 + lines.len() * 10) * scale
}

/// A box of the overlay: its left and top pixel and its size.
#[derive(Clone, Copy)]
pub struct Area {
    pub left: usize,
    pub top: usize,
    pub width: usize,
    pub height: usize,
}

impl Area {
    /// Sets `(x, y)` of the area (from its top-left) in `rgba`, `width` pixels a row, where
    /// the image has it.
    fn put(&self, rgba: &mut [u8], width: usize, (x, y): (usize, usize), c: [u8; 4]) {
        let (x, y) = (self.left + x, self.top + y);
        if x < width && 4 * (y * width + x) + 4 <= rgba.len() {
            let p = 4 * (y * width + x);
            rgba[p..p + 4].copy_from_slice(&c);
        }
    }
}

/// Draws curves of (x, y) points, y on a log scale, each in its colour, over a dark box
/// `area` of an RGBA8 image `width` pixels wide; both axes span all the points.
pub fn draw_curves(rgba: &mut [u8], width: usize, area: Area, curves: &[(&[[f64; 2]], [u8; 3])]) {
    let (w, h) = (area.width.max(2), area.height.max(2));
    for p in 0..w * h {
        area.put(rgba, width, (p % w, p / w), [16, 16, 16, 200]);
    }
    let points = || {
        curves
            .iter()
            .flat_map(|(c, _)| c.iter())
            .filter(|p| p[1] > 0.0)
    };
    let span = |f: &dyn Fn(&[f64; 2]) -> f64| {
        points()
            .map(f)
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], v| {
                [a.min(v), b.max(v)]
            })
    };
    let [x0, x1] = span(&|p| p[0]);
    let [y0, y1] = span(&|p| p[1].ln());
    if !x0.is_finite() {
        return;
    }
    let at = |v: f64, [a, b]: [f64; 2], n: usize| {
        (((v - a) / (b - a).max(1e-12)) * (n - 1) as f64).round() as usize
    };
    for (curve, [r, g, b]) in curves {
        let placed: Vec<[usize; 2]> = (curve.iter().filter(|p| p[1] > 0.0))
            .map(|p| [at(p[0], [x0, x1], w), h - 1 - at(p[1].ln(), [y0, y1], h)])
            .collect();
        // Each point joined to the next by a straight run of pixels.
        for (i, &[xa, ya]) in placed.iter().enumerate() {
            let [xb, yb] = placed.get(i + 1).copied().unwrap_or([xa, ya]);
            let n = xa.abs_diff(xb).max(ya.abs_diff(yb)).max(1);
            for k in 0..=n {
                let lerp = |a: usize, b: usize| {
                    (a as f64 + (b as f64 - a as f64) * k as f64 / n as f64).round() as usize
                };
                area.put(rgba, width, (lerp(xa, xb), lerp(ya, yb)), [*r, *g, *b, 255]);
            }
        }
    }
}

/// Draws the colour scale `colour` (of 0 at the left to 1 at the right, sRGB 0..1) over
/// `area` of an RGBA8 image `width` pixels wide.
pub fn draw_scale(rgba: &mut [u8], width: usize, area: Area, colour: impl Fn(f32) -> [f32; 3]) {
    for x in 0..area.width {
        let c =
            colour(x as f32 / (area.width.max(2) - 1) as f32).map(|v| (v * 255.0).round() as u8);
        for y in 0..area.height {
            area.put(rgba, width, (x, y), [c[0], c[1], c[2], 255]);
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
        draw_lines(&mut rgba, 64, 64, &["I".into()], 1);
        let lit: Vec<usize> = (0..64 * 32).filter(|&p| rgba[4 * p] == 255).collect();
        assert!(
            !lit.is_empty() && lit.iter().all(|&p| p % 64 < 16 && p / 64 < 16),
            "{lit:?}"
        );
    }

    #[test]
    fn a_falling_curve_is_drawn_from_the_top_left_to_the_bottom_right_of_its_box() {
        let mut rgba = vec![0; 4 * 40 * 30];
        let area = Area {
            left: 5,
            top: 4,
            width: 21,
            height: 11,
        };
        let falling = [[0.0, 1.0], [5.0, 0.1], [10.0, 0.01]];
        draw_curves(&mut rgba, 40, area, &[(&falling, [255, 0, 0])]);
        let red =
            |x: usize, y: usize| rgba[4 * (y * 40 + x)..4 * (y * 40 + x) + 4] == [255, 0, 0, 255];
        assert!(
            red(5, 4) && red(15, 9) && red(25, 14),
            "ends and middle on the log scale"
        );
        assert!(red(10, 6) || red(10, 7), "the points joined");
        assert_eq!(rgba[4 * (3 * 40 + 5) + 3], 0, "nothing above the box");
        assert_eq!(
            rgba[4 * (4 * 40 + 6) + 3],
            200,
            "the box is dark and translucent"
        );
    }
}
