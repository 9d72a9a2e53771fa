//! Text on pictures: the public-domain 8 × 8 bitmap font of the `font8x8` crate (ASCII), drawn
//! into sRGB pixel buffers at an integer scale.

use font8x8::UnicodeFonts;

/// Width (and height) of one character at scale 1, in pixels.
pub(super) const GLYPH: usize = 8;

/// An RGB8 picture being annotated: `3 · width · height` bytes, rows top to bottom.
pub(crate) struct Canvas<'a> {
    pub rgb: &'a mut [u8],
    pub width: usize,
    pub height: usize,
}

impl Canvas<'_> {
    /// Sets one pixel; pixels outside the picture are ignored.
    pub(super) fn put(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if x < 0 || y < 0 || x as usize >= self.width || y as usize >= self.height {
            return;
        }
        let i = 3 * (y as usize * self.width + x as usize);
        self.rgb[i..i + 3].copy_from_slice(&c);
    }

    /// Fills the rectangle `[x, x + w) × [y, y + h)` (clipped to the picture).
    pub(super) fn fill(&mut self, x: i64, y: i64, w: i64, h: i64, c: [u8; 3]) {
        for yy in y.max(0)..(y + h).min(self.height as i64) {
            for xx in x.max(0)..(x + w).min(self.width as i64) {
                self.put(xx, yy, c);
            }
        }
    }

    /// Draws `s` with its top-left corner at `(x, y)`, each font pixel a `scale × scale` square.
    /// Characters outside ASCII are drawn as `?`.
    pub(super) fn text(&mut self, x: i64, y: i64, s: &str, scale: usize, c: [u8; 3]) {
        let k = scale.max(1) as i64;
        for (n, ch) in s.chars().enumerate() {
            let glyph = font8x8::BASIC_FONTS
                .get(ch)
                .or_else(|| font8x8::BASIC_FONTS.get('?'))
                .unwrap_or([0; 8]);
            let x0 = x + n as i64 * GLYPH as i64 * k;
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..GLYPH {
                    if bits & (1 << col) != 0 {
                        self.fill(x0 + col as i64 * k, y + row as i64 * k, k, k, c);
                    }
                }
            }
        }
    }
}

/// Width of `s` in pixels at `scale`.
pub(super) fn text_width(s: &str, scale: usize) -> usize {
    s.chars().count() * GLYPH * scale.max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digits_are_drawn_inside_their_cell_and_differ() {
        let (w, h) = (40, 10);
        let draw = |s: &str| {
            let mut rgb = vec![255u8; 3 * w * h];
            Canvas {
                rgb: &mut rgb,
                width: w,
                height: h,
            }
            .text(1, 1, s, 1, [0, 0, 0]);
            rgb
        };
        let one = draw("1");
        let seven = draw("7");
        assert_ne!(one, seven);
        // Ink only inside the 8 × 8 cell at (1, 1).
        for y in 0..h {
            for x in 0..w {
                let inked = one[3 * (y * w + x)] == 0;
                if inked {
                    assert!((1..9).contains(&x) && (1..9).contains(&y), "({x}, {y})");
                }
            }
        }
        assert!(one.contains(&0));
        assert_eq!(text_width("-1.5e-3", 2), 7 * 16);
    }
}
