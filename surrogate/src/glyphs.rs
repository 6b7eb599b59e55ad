//! Text for the PNG pictures without a system font: the public-domain 8 x 8 bitmap glyphs of
//! the `font8x8` crate (basic Latin), scaled by an integer factor. A fresh machine has no
//! fonts (plotters' TrueType text needs one), and a picture whose title states the position,
//! force and time it shows must carry that title everywhere.

use font8x8::legacy::BASIC_LEGACY;

/// Width and height (px) of one glyph cell at scale 1.
pub const CELL: i32 = 8;

/// Width (px) of `text` at `scale`.
pub fn text_width(text: &str, scale: i32) -> i32 {
    text.chars().count() as i32 * CELL * scale
}

/// Calls `put(x, y)` for every pixel of `text` drawn with its top-left corner at (`x`, `y`),
/// each glyph pixel a `scale` x `scale` block. Characters outside basic Latin print as `?`.
pub fn for_each_pixel(text: &str, x: i32, y: i32, scale: i32, mut put: impl FnMut(i32, i32)) {
    for (k, ch) in text.chars().enumerate() {
        let code = if (ch as u32) < 128 {
            ch as usize
        } else {
            '?' as usize
        };
        let glyph = BASIC_LEGACY[code];
        let x0 = x + k as i32 * CELL * scale;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits >> col & 1 == 1 {
                    for dy in 0..scale {
                        for dx in 0..scale {
                            put(x0 + col * scale + dx, y + row as i32 * scale + dy);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 'I' in font8x8 is a 4-pixel-wide cap and foot around a 2-pixel stem of 5 rows:
    /// 4 + 2 * 5 + 4 = 18 pixels at scale 1, four times that at scale 2.
    #[test]
    fn glyph_pixels() {
        let mut n = 0;
        for_each_pixel("I", 0, 0, 1, |_, _| n += 1);
        assert_eq!(n, 18);
        let mut m = 0;
        let (mut xmax, mut ymax) = (0, 0);
        for_each_pixel(" I", 0, 0, 2, |x, y| {
            m += 1;
            xmax = xmax.max(x);
            ymax = ymax.max(y);
        });
        assert_eq!(m, 72);
        assert!(xmax >= 16 && xmax < 32 && ymax < 16);
        assert_eq!(text_width("kPa", 2), 48);
    }
}
