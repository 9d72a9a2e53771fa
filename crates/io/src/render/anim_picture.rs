//! Pictures of animations: an animated PNG (APNG) or GIF written frame by frame, and a contact
//! sheet (a grid of frames with their times in one picture).
//!
//! The APNG keeps the renderer's full colour. The GIF has 256 colours per frame: each frame gets
//! its own palette (its own colours when it has at most 256, else NeuQuant's 256 through
//! `color_quant`) and every pixel the nearest colour of that palette, without dithering, so a
//! pixel's error is exactly its distance to the palette ([`quantize`]).

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

/// The delay between GIF frames for a time step `dt` (seconds): hundredths of a second (the
/// GIF's unit), rounded to the nearest and at least 1; `dt` must be finite and positive and is
/// clamped to 655.35 s.
pub fn gif_delay(dt: f64) -> Result<u16> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::invalid(format!(
            "the time between frames must be finite and positive (got {dt})"
        )));
    }
    Ok((dt * 100.0).round().clamp(1.0, u16::MAX as f64) as u16)
}

/// A frame reduced to at most 256 colours: `palette` (RGB triples) and one index per pixel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Quantized {
    /// The colours, at most 256, as RGB triples (three bytes each).
    pub palette: Vec<u8>,
    /// One palette index per pixel, rows top to bottom.
    pub indices: Vec<u8>,
}

/// NeuQuant's sampling factor (1 learns from every pixel, 10 from one in 10): 10, its authors'
/// balance of speed and quality, where that still leaves 64 samples for each of the 256
/// colours; every pixel for frames of 16 384 pixels or fewer.
fn neuquant_sampling(pixels: usize) -> i32 {
    (pixels / (256 * 64)).clamp(1, 10) as i32
}

/// Reduces RGB8 pixels to a palette of at most 256 colours. A frame of at most 256 colours keeps
/// them exactly; otherwise the palette is NeuQuant's (`color_quant`). Either way each pixel gets
/// the palette colour nearest to it in squared RGB distance (ties to the lower index), so its
/// error is the distance from its colour to the palette and no more.
pub fn quantize(rgb: &[u8]) -> Quantized {
    use std::collections::{BTreeSet, HashMap};
    let key = |p: &[u8]| (p[0] as u32) << 16 | (p[1] as u32) << 8 | p[2] as u32;
    let mut colours = BTreeSet::new();
    for p in rgb.chunks_exact(3) {
        colours.insert(key(p));
        if colours.len() > 256 {
            break;
        }
    }
    let palette: Vec<u8> = if colours.len() <= 256 {
        colours
            .iter()
            .flat_map(|&c| [(c >> 16) as u8, (c >> 8) as u8, c as u8])
            .collect()
    } else {
        let rgba: Vec<u8> = rgb
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect();
        color_quant::NeuQuant::new(neuquant_sampling(rgb.len() / 3), 256, &rgba).color_map_rgb()
    };
    let mut nearest: HashMap<u32, u8> = HashMap::new();
    let indices = rgb
        .chunks_exact(3)
        .map(|p| {
            *nearest
                .entry(key(p))
                .or_insert_with(|| nearest_colour(&palette, p))
        })
        .collect();
    Quantized { palette, indices }
}

/// Index of the colour of `palette` nearest to `p` (squared RGB distance, the lowest index of
/// equals).
fn nearest_colour(palette: &[u8], p: &[u8]) -> u8 {
    let mut best = (u32::MAX, 0u8);
    for (i, c) in palette.chunks_exact(3).enumerate() {
        let d: u32 = (0..3)
            .map(|k| (c[k] as i32 - p[k] as i32).pow(2) as u32)
            .sum();
        if d < best.0 {
            best = (d, i as u8);
        }
    }
    best.1
}

/// An animated GIF being written: frames of one size, each with its own palette, played in a
/// loop for ever.
pub struct Gif<W: Write> {
    encoder: gif::Encoder<W>,
    width: u16,
    height: u16,
    delay: u16,
    frames: u32,
    written: u32,
}

impl<W: Write> Gif<W> {
    /// Starts a GIF of `frames` frames of `width × height` pixels (each side 1 to 65 535 and at
    /// most the renderer's largest picture), each shown for `delay` hundredths of a second
    /// ([`gif_delay`]), repeating for ever.
    pub fn new(w: W, width: u32, height: u32, frames: u32, delay: u16) -> Result<Self> {
        let side = super::MAX_SIDE.min(u16::MAX as u32);
        if width == 0 || height == 0 || width > side || height > side {
            return Err(Error::invalid(format!(
                "{width} × {height} pixels; each side 1 to {side}"
            ))
            .at("size"));
        }
        if frames == 0 {
            return Err(Error::invalid("an animation needs at least one frame"));
        }
        let (width, height) = (width as u16, height as u16);
        let err = |e: gif::EncodingError| Error::io(format!("GIF: {e}"));
        let mut encoder = gif::Encoder::new(w, width, height, &[]).map_err(err)?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(err)?;
        Ok(Gif {
            encoder,
            width,
            height,
            delay,
            frames,
            written: 0,
        })
    }

    /// Appends the next frame (`3 · width · height` bytes of RGB8, rows top to bottom).
    pub fn push(&mut self, rgb: &[u8]) -> Result<()> {
        self.check_len(rgb.len(), 3)?;
        self.push_quantized(&quantize(rgb))
    }

    /// Appends the next frame, already quantised (frames may be quantised in parallel).
    pub fn push_quantized(&mut self, q: &Quantized) -> Result<()> {
        self.check_len(q.indices.len(), 1)?;
        if q.palette.is_empty() || q.palette.len() > 3 * 256 || !q.palette.len().is_multiple_of(3) {
            return Err(Error::invalid(format!(
                "a palette of {} bytes (1 to 256 RGB colours expected)",
                q.palette.len()
            )));
        }
        if let Some(&i) = q
            .indices
            .iter()
            .find(|&&i| 3 * i as usize >= q.palette.len())
        {
            return Err(Error::invalid(format!(
                "colour index {i} outside the frame's palette of {} colours",
                q.palette.len() / 3
            )));
        }
        if self.written == self.frames {
            return Err(Error::invalid(format!(
                "more frames than the {} announced",
                self.frames
            )));
        }
        let frame = gif::Frame {
            width: self.width,
            height: self.height,
            delay: self.delay,
            palette: Some(q.palette.clone()),
            buffer: std::borrow::Cow::Borrowed(&q.indices),
            ..gif::Frame::default()
        };
        self.encoder
            .write_frame(&frame)
            .map_err(|e| Error::io(format!("GIF frame {}: {e}", self.written + 1)))?;
        self.written += 1;
        Ok(())
    }

    fn check_len(&self, len: usize, per_pixel: usize) -> Result<()> {
        let expected = per_pixel * self.width as usize * self.height as usize;
        if len == expected {
            Ok(())
        } else {
            Err(Error::invalid(format!(
                "{len} bytes for a {} × {} frame (expected {expected})",
                self.width, self.height
            )))
        }
    }

    /// Ends the file (writes the trailer); every announced frame must have been written.
    pub fn finish(self) -> Result<W> {
        if self.written != self.frames {
            return Err(Error::invalid(format!(
                "{} of the {} announced frames written",
                self.written, self.frames
            )));
        }
        self.encoder
            .into_inner()
            .map_err(|e| Error::io(format!("GIF end: {e}")))
    }
}

/// Tiles of equal size gathered into a grid, each with a caption.
pub struct ContactSheet {
    /// Width of every tile, in pixels.
    pub tile_width: u32,
    /// Height of every tile, in pixels.
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
    fn gif_delays_are_hundredths_rounded() {
        assert_eq!(gif_delay(1.0 / 12.0).unwrap(), 8);
        assert_eq!(gif_delay(0.8 / 48.0).unwrap(), 2);
        assert_eq!(gif_delay(0.04).unwrap(), 4);
        assert_eq!(gif_delay(1e-4).unwrap(), 1, "at least one hundredth");
        assert_eq!(gif_delay(1e6).unwrap(), u16::MAX);
        assert!(gif_delay(0.0).is_err() && gif_delay(f64::INFINITY).is_err());
    }

    /// A decoded GIF: loop count, width, height, and per frame (delay, palette, indices).
    type Decoded = (gif::Repeat, u16, u16, Vec<(u16, Vec<u8>, Vec<u8>)>);

    /// Decodes a GIF with the `gif` crate.
    fn decode_gif(bytes: &[u8]) -> Decoded {
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::Indexed);
        let mut d = options.read_info(std::io::Cursor::new(bytes)).unwrap();
        let mut frames = Vec::new();
        while let Some(f) = d.read_next_frame().unwrap() {
            assert_eq!((f.left, f.top), (0, 0));
            let palette = f.palette.clone().expect("a palette of its own");
            frames.push((f.delay, palette, f.buffer.to_vec()));
        }
        (d.repeat(), d.width(), d.height(), frames)
    }

    /// The colour a decoded frame shows at pixel `i`.
    fn shown(palette: &[u8], indices: &[u8], i: usize) -> [u8; 3] {
        let c = 3 * indices[i] as usize;
        [palette[c], palette[c + 1], palette[c + 2]]
    }

    fn dist2(a: &[u8], b: &[u8]) -> u32 {
        (0..3)
            .map(|k| (a[k] as i32 - b[k] as i32).pow(2) as u32)
            .sum()
    }

    /// Written, then decoded by the `gif` crate: size, loop for ever, delays, and pixels. A frame
    /// of at most 256 colours comes back exactly; a frame of 4 096 colours comes back with every
    /// pixel at the colour of its palette nearest to the original (no palette colour is closer),
    /// which is the whole of the quantisation error.
    #[test]
    fn gif_decodes_back_with_each_pixel_at_its_nearest_palette_colour() {
        let (w, h) = (256u32, 256u32);
        // Frame 0: 200 colours. Frame 1: a smooth ramp of 65 536 colours (like shading).
        let few: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let k = (i % 200) as u8;
                [k, 255 - k, k / 2]
            })
            .collect();
        let ramp: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                let (x, y) = (i % w, i / w);
                [x as u8, y as u8, 128]
            })
            .collect();
        let mut bytes = Vec::new();
        let mut g = Gif::new(&mut bytes, w, h, 2, 4).unwrap();
        g.push(&few).unwrap();
        g.push(&ramp).unwrap();
        assert!(g.push(&few).is_err(), "a third frame is refused");
        g.finish().unwrap();
        let (repeat, dw, dh, frames) = decode_gif(&bytes);
        assert_eq!(repeat, gif::Repeat::Infinite);
        assert_eq!((dw as u32, dh as u32), (w, h));
        assert_eq!(frames.len(), 2);
        let (delay, palette, indices) = &frames[0];
        assert_eq!(*delay, 4);
        for (i, p) in few.chunks_exact(3).enumerate() {
            assert_eq!(shown(palette, indices, i), [p[0], p[1], p[2]], "pixel {i}");
        }
        let (delay, palette, indices) = &frames[1];
        assert_eq!(*delay, 4);
        assert!(palette.len() <= 3 * 256);
        let mut total = 0u64;
        for (i, p) in ramp.chunks_exact(3).enumerate() {
            let got = shown(palette, indices, i);
            let best = palette.chunks_exact(3).map(|c| dist2(c, p)).min().unwrap();
            assert_eq!(dist2(&got, p), best, "pixel {i}: {p:?} shown as {got:?}");
            total += best as u64;
        }
        // 65 536 colours on 256: the palette does quantise (some error), and stays near the
        // colours. The best 256 cells would be squares of 16 × 16 ramp colours: mean square
        // distance to the centre 2·(16² − 1)/12 = 42.5. NeuQuant is not optimal; within twice
        // that RMS.
        let rms = (total as f64 / (w * h) as f64).sqrt();
        assert!(rms > 0.0 && rms < 2.0 * 42.5f64.sqrt(), "rms {rms}");
    }

    #[test]
    fn bad_gifs_are_refused() {
        let mut bytes = Vec::new();
        let mut g = Gif::new(&mut bytes, 2, 2, 2, 5).unwrap();
        assert!(g.push(&[0; 11]).is_err());
        let bad = Quantized {
            palette: vec![0; 6],
            indices: vec![0, 1, 2, 0],
        };
        assert!(g.push_quantized(&bad).is_err(), "index outside the palette");
        g.push(&[0; 12]).unwrap();
        assert!(g.finish().is_err(), "one of two frames");
        assert!(Gif::new(Vec::new(), 0, 2, 3, 5).is_err());
        assert!(Gif::new(Vec::new(), 70_000, 2, 3, 5).is_err());
        assert!(Gif::new(Vec::new(), 2, 2, 0, 5).is_err());
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
