//! PNG pictures that need nothing from the machine they are drawn on.
//!
//! plotters' default text path (`ttf`) asks fontconfig for a system font and links
//! libfontconfig and libfreetype; a bare compute node has neither, and a plot drawn there has
//! no title, no tick labels and no legend. palpa instead embeds one font, DejaVu Sans
//! (Bitstream Vera licence, `fonts/LICENSE-DejaVu.txt`), subset to Latin-1, Greek, arrows and
//! the mathematical signs the plots print (57 KB), and registers it with plotters' `ab_glyph`
//! text path under every generic family name. The binary then links only the C library, and
//! a plot whose text cannot be drawn is an error, never a silent picture without words.
//!
//! Pictures are drawn into memory ([`plotters::prelude::BitMapBackend::with_buffer`]) and
//! encoded by [`encode_png`], so that the caller writes the file in one atomic step.

use plotters::style::FontStyle;
use std::sync::Once;

/// The embedded font: DejaVu Sans 2.37, subset (see the module doc).
pub const FONT: &[u8] = include_bytes!("../fonts/DejaVuSans-subset.ttf");

/// The generic family names plotters' styles use; each is drawn with [`FONT`].
pub const FAMILIES: [&str; 3] = ["sans-serif", "serif", "monospace"];

static REGISTER: Once = Once::new();

/// Registers [`FONT`] with plotters for every family in [`FAMILIES`] and every style (once per
/// process). Call before drawing text.
pub fn register_fonts() {
    REGISTER.call_once(|| {
        for family in FAMILIES {
            for style in [
                FontStyle::Normal,
                FontStyle::Oblique,
                FontStyle::Italic,
                FontStyle::Bold,
            ] {
                // the font is compiled in, and a test draws with it; should it ever fail to
                // parse, text drawing fails with plotters' "font unavailable" error
                let _ = plotters::style::register_font(family, style, FONT);
            }
        }
    });
}

/// Encodes an 8-bit RGB buffer of `w` x `h` pixels as PNG bytes.
pub fn encode_png(rgb8: &[u8], w: u32, h: u32) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc.write_header().map_err(|e| e.to_string())?;
        wr.write_image_data(rgb8).map_err(|e| e.to_string())?;
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    /// Text drawn with the embedded font puts ink on the picture: a caption on white leaves
    /// dark pixels in its box and none elsewhere.
    #[test]
    fn text_is_drawn_without_a_system_font() {
        register_fonts();
        let (w, h) = (200u32, 60u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            root.fill(&WHITE).unwrap();
            root.draw(&Text::new(
                "K/G = 5e4, ν, μ",
                (10, 20),
                ("sans-serif", 20).into_font(),
            ))
            .unwrap();
            root.present().unwrap();
        }
        let dark = buf.chunks(3).filter(|p| p[0] < 128).count();
        assert!(
            dark > 100,
            "only {dark} dark pixels: the text was not drawn"
        );
        // nothing above the text's top edge (y < 15)
        let above = buf[..(15 * w * 3) as usize]
            .chunks(3)
            .filter(|p| p[0] < 128)
            .count();
        assert_eq!(above, 0);
    }

    /// The PNG encoder's output decodes to the same pixels.
    #[test]
    fn png_round_trip() {
        let (w, h) = (3u32, 2u32);
        let rgb: Vec<u8> = (0..(w * h * 3) as u8).collect();
        let bytes = encode_png(&rgb, w, h).unwrap();
        let dec = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = dec.read_info().unwrap();
        let mut out = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut out).unwrap();
        assert_eq!(out, rgb);
    }
}
