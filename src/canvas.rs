//! An 8-bit RGB canvas with an 8 x 8 bitmap font: the comparison's
//! composites and the colour bars of observed images.

/// An 8-bit RGB canvas.
pub struct Canvas {
    /// Width.
    pub width: usize,
    /// Height.
    pub height: usize,
    /// Row-major RGB bytes.
    pub rgb: Vec<u8>,
}

impl Canvas {
    /// A canvas filled with one colour.
    pub fn new(width: usize, height: usize, fill: [u8; 3]) -> Canvas {
        Canvas {
            width,
            height,
            rgb: fill
                .iter()
                .copied()
                .cycle()
                .take(width * height * 3)
                .collect(),
        }
    }

    /// Copies an RGB image in at (x0, y0).
    pub fn paste(&mut self, x0: usize, y0: usize, w: usize, h: usize, rgb: &[u8]) {
        for y in 0..h.min(self.height.saturating_sub(y0)) {
            let n = w.min(self.width.saturating_sub(x0)) * 3;
            let dst = ((y0 + y) * self.width + x0) * 3;
            self.rgb[dst..dst + n].copy_from_slice(&rgb[y * w * 3..y * w * 3 + n]);
        }
    }

    /// Sets one pixel (ignored outside).
    pub fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = (y * self.width + x) * 3;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// Draws text with the 8x8 bitmap font, each font pixel `scale` pixels.
    pub fn text(&mut self, x0: usize, y0: usize, scale: usize, text: &str, c: [u8; 3]) {
        use font8x8::UnicodeFonts;
        for (k, ch) in text.chars().enumerate() {
            let glyph = font8x8::BASIC_FONTS.get(ch).unwrap_or([0; 8]);
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits & (1 << col) != 0 {
                        for dy in 0..scale {
                            for dx in 0..scale {
                                self.set(x0 + (k * 8 + col) * scale + dx, y0 + row * scale + dy, c);
                            }
                        }
                    }
                }
            }
        }
    }
}
