//! `pdeshape animate --gif`: an animated GIF decoded back by the `gif` crate and compared with
//! the APNG of the same run (the same rendered frames at full colour), and the frames written
//! by `--frames-dir` in the same run.

use crate::common::*;

fn ventricle() -> PathBuf {
    example_path("anim/ventricle.toml")
}

/// Every frame of an APNG as RGB8 (the `png` crate's decoder).
fn apng_frames(bytes: &[u8]) -> (u32, u32, Vec<Vec<u8>>) {
    let mut r = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let (w, h) = (r.info().width, r.info().height);
    let n = r.info().animation_control.unwrap().num_frames;
    let mut frames = Vec::new();
    let mut buf = vec![0; r.output_buffer_size()];
    for _ in 0..n {
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (w, h), "full frames");
        frames.push(buf[..(3 * w * h) as usize].to_vec());
    }
    (w, h, frames)
}

/// Loop count, size and per frame (delay, palette, indices) of a GIF (the `gif` crate).
type GifFrames = (gif::Repeat, (u16, u16), Vec<(u16, Vec<u8>, Vec<u8>)>);

fn gif_frames(bytes: &[u8]) -> GifFrames {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut d = options.read_info(std::io::Cursor::new(bytes)).unwrap();
    let (w, h) = (d.width(), d.height());
    let global = d.global_palette().map(<[u8]>::to_vec);
    let mut frames = Vec::new();
    while let Some(f) = d.read_next_frame().unwrap() {
        assert_eq!((f.left, f.top, f.width, f.height), (0, 0, w, h));
        let palette = f.palette.clone().or(global.clone());
        frames.push((f.delay, palette.unwrap(), f.buffer.to_vec()));
    }
    (d.repeat(), (w, h), frames)
}

fn dist2(a: &[u8], b: &[u8]) -> u32 {
    (0..3)
        .map(|k| (a[k] as i32 - b[k] as i32).pow(2) as u32)
        .sum()
}

/// The GIF loops, has one frame per frame of [time] with the delay of [time] in hundredths
/// (0.8 s / 48 = 1.67 → 2), and every pixel is the colour of its frame's palette nearest to the
/// APNG's pixel: the quantisation's error and nothing else.
#[test]
fn the_gif_loops_and_each_pixel_is_the_nearest_palette_colour_of_the_apng_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let (glb, apng, gif, frames_dir) = (
        dir.path().join("v.glb"),
        dir.path().join("v.png"),
        dir.path().join("v.gif"),
        dir.path().join("frames"),
    );
    let v = ventricle();
    let out = pdeshape(&[
        "animate",
        s(&v),
        "-o",
        s(&glb),
        "--nu",
        "12",
        "--nv",
        "24",
        "--apng",
        s(&apng),
        "--gif",
        s(&gif),
        "--frames-dir",
        s(&frames_dir),
        "--picture-size",
        "96x72",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("v.gif"), "{said}");
    let (w, h, full) = apng_frames(&std::fs::read(&apng).unwrap());
    assert_eq!((w, h, full.len()), (96, 72, 48));
    let (repeat, size, frames) = gif_frames(&std::fs::read(&gif).unwrap());
    assert_eq!(repeat, gif::Repeat::Infinite);
    assert_eq!(size, (96, 72));
    assert_eq!(frames.len(), 48);
    let (mut worst, mut total, mut exact) = (0u32, 0u64, 0usize);
    for (k, ((delay, palette, indices), rgb)) in frames.iter().zip(&full).enumerate() {
        assert_eq!(*delay, 2, "frame {k}");
        assert!(palette.len() <= 3 * 256 && palette.len().is_multiple_of(3));
        for (i, p) in rgb.chunks_exact(3).enumerate() {
            let c = 3 * indices[i] as usize;
            let got = &palette[c..c + 3];
            let best = palette.chunks_exact(3).map(|q| dist2(q, p)).min().unwrap();
            assert_eq!(
                dist2(got, p),
                best,
                "frame {k} pixel {i}: {p:?} shown as {got:?}"
            );
            worst = worst.max(best);
            total += best as u64;
            exact += (best == 0) as usize;
        }
    }
    // The frames are not all of few colours (the shading was quantised somewhere), and the
    // frames do differ from one another (the heart moves).
    assert!(worst > 0, "no pixel needed quantising");
    assert!(exact > 0);
    assert_ne!(full[0], full[12]);
    let pixels = 48 * 96 * 72;
    eprintln!(
        "GIF vs APNG: largest squared error {worst}, RMS {:.2}, exact pixels {:.1} %",
        (total as f64 / pixels as f64).sqrt(),
        100.0 * exact as f64 / pixels as f64
    );
    // --frames-dir in the same pass: one picture per frame.
    let mut names: Vec<String> = std::fs::read_dir(&frames_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), 48);
    assert_eq!(
        (names[0].as_str(), names[47].as_str()),
        ("frame_0000.png", "frame_0047.png")
    );
}

#[test]
fn a_bad_gif_flag_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("v.glb");
    let bad = dir.path().join("v.png");
    let v = ventricle();
    let out = pdeshape(&["animate", s(&v), "-o", s(&glb), "--gif", s(&bad)]);
    assert_bad(&out, &["--gif", "v.png", ".gif"]);
    assert!(files(dir.path()).is_empty(), "nothing is left behind");
}
