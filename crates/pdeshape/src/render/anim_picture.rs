//! Pictures of animations: an animated PNG (APNG) written frame by frame, and a contact sheet
//! (a grid of frames with their times in one picture).
//!
//! APNG rather than GIF: the frames keep the renderer's full colour (a GIF has 256 colours per
//! frame and would dither the shading), browsers play it, and the `png` crate the renderer
//! already uses writes it.

use super::text::{Canvas, GLYPH};
use crate::{Error, Result};
use std::io::Write;

/// The delay between frames `dt` (seconds) as the fraction `num / den` of an APNG frame
/// control: the smallest denominator up to 1000 that gives `dt` exactly (to `10⁻⁹` s), else
/// milliseconds. `dt` must be finite and positive; it is clamped to `[1 ms, 65.535 s]`.
pub fn frame_delay(dt: f64) -> Result<(u16, u16)> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::invalid(format!(
            "the time between frames must be finite and positive (got {dt})"
        )));
    }
    let dt = dt.clamp(1e-3, 65.535);
    for den in 1..=1000u16 {
        let num = (dt * den as f64).round();
        if num >= 1.0 && num <= u16::MAX as f64 && (num / den as f64 - dt).abs() < 1e-9 {
            return Ok((num as u16, den));
        }
    }
    Ok(((dt * 1000.0).round().max(1.0) as u16, 1000))
}

/// An animated PNG being written: RGB8 frames of one size, played in a loop for ever.
pub struct Apng<W: Write> {
    writer: png::Writer<W>,
    width: u32,
    height: u32,
    frames: u32,
    written: u32,
}

impl<W: Write> Apng<W> {
    /// Starts an APNG of `frames` frames of `width × height` pixels, each shown for
    /// `delay.0 / delay.1` seconds, repeating for ever.
    pub fn new(w: W, width: u32, height: u32, frames: u32, delay: (u16, u16)) -> Result<Self> {
        if width == 0 || height == 0 || width > super::MAX_SIDE || height > super::MAX_SIDE {
            return Err(Error::invalid(format!(
                "{width} × {height} pixels; each side 1 to {}",
                super::MAX_SIDE
            ))
            .at("size"));
        }
        if frames == 0 {
            return Err(Error::invalid("an animation needs at least one frame"));
        }
        let err = |e: png::EncodingError| Error::io(format!("APNG: {e}"));
        let mut enc = png::Encoder::new(w, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        enc.set_animated(frames, 0).map_err(err)?;
        enc.set_frame_delay(delay.0, delay.1).map_err(err)?;
        let writer = enc.write_header().map_err(err)?;
        Ok(Apng {
            writer,
            width,
            height,
            frames,
            written: 0,
        })
    }

    /// Appends the next frame (`3 · width · height` bytes, rows top to bottom).
    pub fn push(&mut self, rgb: &[u8]) -> Result<()> {
        let expected = 3 * self.width as usize * self.height as usize;
        if rgb.len() != expected {
            return Err(Error::invalid(format!(
                "{} bytes of pixels for a {} × {} frame (expected {expected})",
                rgb.len(),
                self.width,
                self.height
            )));
        }
        if self.written == self.frames {
            return Err(Error::invalid(format!(
                "more frames than the {} announced",
                self.frames
            )));
        }
        self.writer
            .write_image_data(rgb)
            .map_err(|e| Error::io(format!("APNG frame {}: {e}", self.written + 1)))?;
        self.written += 1;
        Ok(())
    }

    /// Ends the file; every announced frame must have been written.
    pub fn finish(self) -> Result<()> {
        if self.written != self.frames {
            return Err(Error::invalid(format!(
                "{} of the {} announced frames written",
                self.written, self.frames
            )));
        }
        self.writer
            .finish()
            .map_err(|e| Error::io(format!("APNG end: {e}")))
    }
}

/// Tiles of equal size gathered into a grid, each with a caption.
pub struct ContactSheet {
    /// Size of every tile, in pixels.
    pub tile_width: u32,
    pub tile_height: u32,
    /// Tiles per row.
    pub columns: u32,
    /// The tiles: RGB8 pixels and the caption drawn in their top-left corner.
    pub tiles: Vec<(Vec<u8>, String)>,
}

/// Space between tiles and around the sheet, in pixels.
const GAP: u32 = 4;

impl ContactSheet {
    /// The sheet's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        let n = self.tiles.len() as u32;
        let cols = self.columns.clamp(1, n.max(1));
        let rows = n.div_ceil(cols).max(1);
        (
            GAP + cols * (self.tile_width + GAP),
            GAP + rows * (self.tile_height + GAP),
        )
    }
}

/// Draws the sheet: tiles row by row on a white background, each caption in black on a white
/// box. Returns the width, height and RGB8 pixels.
pub fn contact_sheet(sheet: &ContactSheet) -> Result<(u32, u32, Vec<u8>)> {
    let (tw, th) = (sheet.tile_width as usize, sheet.tile_height as usize);
    let (w, h) = sheet.size();
    if w > super::MAX_SIDE || h > super::MAX_SIDE {
        return Err(Error::invalid(format!(
            "the contact sheet would be {w} × {h} pixels; at most {} a side",
            super::MAX_SIDE
        )));
    }
    let cols = sheet.columns.clamp(1, (sheet.tiles.len() as u32).max(1)) as usize;
    let (w, h) = (w as usize, h as usize);
    let mut rgb = vec![255u8; 3 * w * h];
    for (k, (tile, caption)) in sheet.tiles.iter().enumerate() {
        if tile.len() != 3 * tw * th {
            return Err(Error::invalid(format!(
                "tile {}: {} bytes for {tw} × {th} pixels",
                k + 1,
                tile.len()
            )));
        }
        let x0 = GAP as usize + (k % cols) * (tw + GAP as usize);
        let y0 = GAP as usize + (k / cols) * (th + GAP as usize);
        for y in 0..th {
            let dst = 3 * ((y0 + y) * w + x0);
            rgb[dst..dst + 3 * tw].copy_from_slice(&tile[3 * y * tw..3 * (y + 1) * tw]);
        }
        let mut canvas = Canvas {
            rgb: &mut rgb,
            width: w,
            height: h,
        };
        let tw_text = super::text::text_width(caption, 1) as i64;
        canvas.fill(
            x0 as i64,
            y0 as i64,
            tw_text + 4,
            GLYPH as i64 + 4,
            [255; 3],
        );
        canvas.text(x0 as i64 + 2, y0 as i64 + 2, caption, 1, [0; 3]);
    }
    Ok((w as u32, h as u32, rgb))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delays_are_exact_fractions_when_they_can_be() {
        assert_eq!(frame_delay(1.0 / 12.0).unwrap(), (1, 12));
        assert_eq!(frame_delay(0.8 / 48.0).unwrap(), (1, 60));
        assert_eq!(frame_delay(0.04).unwrap(), (1, 25));
        assert_eq!(frame_delay(2.5).unwrap(), (5, 2));
        assert_eq!(frame_delay(1.0 / 7.0 + 1e-4).unwrap(), (143, 1000));
        assert!(frame_delay(0.0).is_err());
        assert!(frame_delay(f64::NAN).is_err());
    }

    /// Written, then decoded by the `png` crate's decoder: frame count, size, plays, delay and
    /// every frame's pixels.
    #[test]
    fn apng_decodes_back() {
        let (w, h, n) = (7u32, 5u32, 4u32);
        let frame = |k: u32| -> Vec<u8> {
            (0..3 * w * h)
                .map(|i| ((i * 7 + k * 50) % 256) as u8)
                .collect()
        };
        let mut bytes = Vec::new();
        let mut a = Apng::new(&mut bytes, w, h, n, (1, 12)).unwrap();
        for k in 0..n {
            a.push(&frame(k)).unwrap();
        }
        assert!(a.push(&frame(0)).is_err(), "a fifth frame is refused");
        a.finish().unwrap();
        let dec = png::Decoder::new(std::io::Cursor::new(&bytes));
        let mut r = dec.read_info().unwrap();
        let info = r.info();
        assert_eq!((info.width, info.height), (w, h));
        let ac = info.animation_control.unwrap();
        assert_eq!((ac.num_frames, ac.num_plays), (n, 0));
        let mut buf = vec![0; r.output_buffer_size()];
        for k in 0..n {
            r.next_frame(&mut buf).unwrap();
            let fc = r.info().frame_control.unwrap();
            assert_eq!((fc.delay_num, fc.delay_den), (1, 12));
            assert_eq!(&buf[..(3 * w * h) as usize], &frame(k)[..], "frame {k}");
        }
    }

    #[test]
    fn unfinished_apng_is_an_error() {
        let mut bytes = Vec::new();
        let mut a = Apng::new(&mut bytes, 2, 2, 3, (1, 10)).unwrap();
        a.push(&[0; 12]).unwrap();
        assert!(a.push(&[0; 11]).is_err());
        assert!(a.finish().is_err());
        assert!(Apng::new(Vec::new(), 0, 2, 3, (1, 10)).is_err());
        assert!(Apng::new(Vec::new(), 2, 2, 0, (1, 10)).is_err());
    }

    #[test]
    fn contact_sheet_places_tiles_in_rows() {
        let tile = |c: u8| vec![c; 3 * 20 * 10];
        let sheet = ContactSheet {
            tile_width: 20,
            tile_height: 10,
            columns: 2,
            tiles: vec![
                (tile(10), String::new()),
                (tile(20), String::new()),
                (tile(30), "t".into()),
            ],
        };
        let (w, h, rgb) = contact_sheet(&sheet).unwrap();
        assert_eq!((w, h), (4 + 2 * 24, 4 + 2 * 14));
        let at = |x: u32, y: u32| rgb[3 * (y * w + x) as usize];
        assert_eq!(at(4 + 19, 4 + 9), 10);
        assert_eq!(at(28 + 10, 4 + 5), 20);
        assert_eq!(at(4 + 15, 18 + 9), 30);
        assert_eq!(at(28 + 10, 18 + 5), 255, "no fourth tile");
        assert_eq!(at(2, 2), 255, "the gap is white");
        // The caption: black glyph pixels inside the third tile's corner.
        let dark = (0..12)
            .flat_map(|y| (0..12).map(move |x| (x, y)))
            .filter(|&(x, y)| at(4 + x, 18 + y) == 0)
            .count();
        assert!(dark > 0);
    }
}
