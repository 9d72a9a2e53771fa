//! `pdeshape animate` with `--retarget`, `--apng` and `--contact-sheet`: bad flags and bad
//! meshes get one line and leave no file; a good run writes every output.

use crate::common::*;

fn ventricle() -> PathBuf {
    example_path("anim/ventricle.toml")
}

/// Three vertices near the ventricle's middle ring and one near its base: two triangles.
const MESH: &str = "v 2.6 0 4.8\nv 0 2.6 4.8\nv -2.6 0 4.8\nv 0 -1.9 8.4\nf 1 2 3\nf 1 3 4\n";

fn run_bad(extra: &[&str], files_in: &[(&str, &str)], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files_in {
        write(dir.path(), name, text);
    }
    let before = files(dir.path());
    let glb = dir.path().join("out.glb");
    let v = ventricle();
    let mut args = vec!["animate", s(&v), "-o", s(&glb), "--nu", "8", "--nv", "16"];
    let owned: Vec<String> = extra
        .iter()
        .map(|a| a.replace("DIR", s(dir.path())))
        .collect();
    args.extend(owned.iter().map(String::as_str));
    let out = pdeshape(&args);
    assert_bad(&out, needles);
    assert_eq!(files(dir.path()), before, "nothing is left behind");
}

#[test]
fn bad_flags_are_refused_before_any_work() {
    run_bad(
        &["--retarget", "DIR/m.obj"],
        &[],
        &["--retarget", "--retarget-output"],
    );
    run_bad(
        &["--retarget-output", "DIR/s.glb"],
        &[],
        &["--retarget-output", "--retarget"],
    );
    run_bad(
        &["--retarget", "DIR/m.txt", "--retarget-output", "DIR/s.glb"],
        &[],
        &[
            "--retarget",
            "m.txt",
            "unknown mesh format (the extension must be obj, stl, ply, off, glb or gltf)",
        ],
    );
    run_bad(
        &["--retarget", "DIR/m.obj", "--retarget-output", "DIR/s.gltf"],
        &[],
        &["--retarget-output", ".glb"],
    );
    run_bad(&["--apng", "DIR/a.gif"], &[], &["--apng", ".png"]);
    run_bad(
        &["--contact-sheet", "DIR/a.jpg"],
        &[],
        &["--contact-sheet", ".png"],
    );
    run_bad(
        &["--apng", "DIR/a.png", "--picture-size", "8x8"],
        &[],
        &["--picture-size", "16"],
    );
    run_bad(
        &["--apng", "DIR/a.png", "--picture-size", "big"],
        &[],
        &["--picture-size"],
    );
    run_bad(
        &["--apng", "DIR/a.png", "--view", "0,0,0"],
        &[],
        &["--view"],
    );
}

#[test]
fn bad_meshes_leave_nothing_behind() {
    run_bad(
        &[
            "--retarget",
            "DIR/none.obj",
            "--retarget-output",
            "DIR/s.glb",
        ],
        &[],
        &["--retarget", "none.obj", "cannot read"],
    );
    run_bad(
        &[
            "--retarget",
            "DIR/m.obj",
            "--retarget-output",
            "DIR/s.glb",
            "--apng",
            "DIR/a.png",
        ],
        &[("m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")],
        &["--retarget", "m.obj"],
    );
    run_bad(
        &["--retarget", "DIR/m.obj", "--retarget-output", "DIR/s.glb"],
        &[("m.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")],
        &["--retarget", "m.obj"],
    );
}

/// Size, frame count, plays and delays (`(num, den)`) of a PNG, read from its chunks.
type Chunks = ((u32, u32), u32, u32, Vec<(u16, u16)>);

fn apng_chunks(bytes: &[u8]) -> Chunks {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let be32 = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    let be16 = |b: &[u8]| u16::from_be_bytes([b[0], b[1]]);
    let (mut pos, mut size, mut frames, mut plays, mut delays) = (8, (0, 0), 0, u32::MAX, vec![]);
    while pos < bytes.len() {
        let len = be32(&bytes[pos..]) as usize;
        let kind = &bytes[pos + 4..pos + 8];
        let body = &bytes[pos + 8..pos + 8 + len];
        match kind {
            b"IHDR" => size = (be32(body), be32(&body[4..])),
            b"acTL" => (frames, plays) = (be32(body), be32(&body[4..])),
            b"fcTL" => delays.push((be16(&body[20..]), be16(&body[22..]))),
            _ => {}
        }
        pos += 12 + len;
    }
    (size, frames, plays, delays)
}

#[test]
fn a_good_run_writes_every_output() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "m.obj", MESH);
    let (glb, sglb, apng, sheet) = (
        dir.path().join("v.glb"),
        dir.path().join("s.glb"),
        dir.path().join("v.png"),
        dir.path().join("sheet.png"),
    );
    let v = ventricle();
    let out = pdeshape(&[
        "animate",
        s(&v),
        "-o",
        s(&glb),
        "--nu",
        "8",
        "--nv",
        "16",
        "--retarget",
        s(&mesh),
        "--retarget-output",
        s(&sglb),
        "--apng",
        s(&apng),
        "--contact-sheet",
        s(&sheet),
        "--picture-size",
        "64x48",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("4 vertices re-targeted"), "{said}");
    // The ventricle: 48 looped frames of 0.8 s, so 1/60 s a frame.
    let (size, frames, plays, delays) = apng_chunks(&std::fs::read(&apng).unwrap());
    assert_eq!((size, frames, plays), ((64, 48), 48, 0));
    assert_eq!(delays, vec![(1, 60); 48]);
    // The contact sheet: 12 tiles of 64 × 48 in 4 columns, 4 pixels apart.
    let (size, frames, _, _) = apng_chunks(&std::fs::read(&sheet).unwrap());
    assert_eq!((size, frames), ((4 + 4 * 68, 4 + 3 * 52), 0));
    let s_bytes = std::fs::read(&sglb).unwrap();
    assert_eq!(&s_bytes[..4], b"glTF");
    assert_eq!(
        files(dir.path()),
        vec!["m.obj", "s.glb", "sheet.png", "v.glb", "v.png"]
    );
}
