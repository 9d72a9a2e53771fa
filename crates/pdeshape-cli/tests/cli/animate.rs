//! End-to-end tests of `pdeshape animate` (and `surface --time`): the outputs, their atomicity
//! on errors, located errors of `[time]` and formula fields, morphs of different structures and
//! the flags.

use crate::common::*;

/// `GOOD` made time-dependent: the rim ellipse's `rx` grows with t over four frames.
fn timed() -> String {
    let text = edit(
        GOOD,
        "[operator]",
        "[time]\nend = 1.0\nframes = 4\n\n[operator]",
    );
    edit(&text, "rx = 1.5", "rx = \"= 1.5 + 0.5*t\"")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

#[test]
fn animate_writes_the_glb_csv_plot_and_pictures() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", &timed());
    let glb = dir.path().join("a.glb");
    let csv = dir.path().join("m.csv");
    let svg = dir.path().join("m.svg");
    let frames = dir.path().join("frames");
    let o = pdeshape(&[
        "animate",
        s(&d),
        "-o",
        s(&glb),
        "--csv",
        s(&csv),
        "--plot",
        s(&svg),
        "--frames-dir",
        s(&frames),
        "--nu",
        "8",
        "--nv",
        "12",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&glb).unwrap();
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
        bytes.len()
    );
    let table = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(table.lines().count(), 1 + 4, "{table}");
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    let pictures = files(&frames);
    assert_eq!(
        pictures,
        [
            "frame_0000.png",
            "frame_0001.png",
            "frame_0002.png",
            "frame_0003.png"
        ]
    );
    let png = std::fs::read(frames.join("frame_0002.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    // Nothing else was left in the directory (no temporary files).
    assert_eq!(
        files(dir.path()),
        ["a.glb", "d.toml", "frames", "m.csv", "m.svg"]
    );
}

#[test]
fn an_error_at_a_later_frame_leaves_no_output_and_keeps_an_old_one() {
    let dir = tempfile::tempdir().unwrap();
    // Fine at t = 0 (where the file is checked), negative radius from t = 2/3 on.
    let text = timed().replace("\"= 1.5 + 0.5*t\"", "\"= 1.5 - 2.4*t\"");
    let d = write(dir.path(), "d.toml", &text);
    let glb = dir.path().join("a.glb");
    let csv = dir.path().join("m.csv");
    std::fs::write(&glb, b"old").unwrap();
    let o = pdeshape(&["animate", s(&d), "-o", s(&glb), "--csv", s(&csv)]);
    let line = assert_bad(&o, &["d.toml", "curves.rim.rx", "at t = 0.6666"]);
    assert!(line.contains("positive"), "{line}");
    assert_eq!(std::fs::read(&glb).unwrap(), b"old");
    assert!(!csv.exists());
    assert_eq!(files(dir.path()), ["a.glb", "d.toml"]);
}

#[test]
fn bad_time_sections_and_formulas_are_located() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("a.glb");
    let cases: [(&str, &str, &[&str]); 5] = [
        (
            "end = 1.0\n",
            "end = -1.0\n",
            &["d.toml:", "time.end", "greater"],
        ),
        ("frames = 4\n", "frames = 1\n", &["d.toml:", "time.frames"]),
        (
            "frames = 4\n",
            "frames = 4\nfps = 10\n",
            &["d.toml:", "time.fps"],
        ),
        (
            "frames = 4\n",
            "frames = 4\nspeed = 2\n",
            &["d.toml:", "speed"],
        ),
        (
            "\"= 1.5 + 0.5*t\"",
            "\"= 1.5 + q*t\"",
            &["d.toml:", "curves.rim.rx", "unknown variable 'q'"],
        ),
    ];
    for (from, to, needles) in cases {
        let d = write(dir.path(), "d.toml", &edit(&timed(), from, to));
        let o = pdeshape(&["animate", s(&d), "-o", s(&glb)]);
        assert_bad(&o, needles);
        assert!(!glb.exists());
    }
}

#[test]
fn a_morph_between_designs_of_different_structure_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let two = GOOD.to_string() + "\n[[spine]]\nmoves = [{ index = 1, by = [0.1, 0.0, 0.0] }]\n";
    write(dir.path(), "a.toml", GOOD);
    write(dir.path(), "b.toml", &two);
    let m = write(
        dir.path(),
        "m.toml",
        "[time]\nframes = 3\n[morph]\nsource = \"a.toml\"\ntarget = \"b.toml\"\n",
    );
    let glb = dir.path().join("m.glb");
    let o = pdeshape(&["animate", s(&m), "-o", s(&glb)]);
    assert_bad(&o, &["m.toml", "morph", "same structure"]);
    assert!(!glb.exists());
    // The same pair in the other order, and a morph that loops, are refused too.
    let m2 = write(
        dir.path(),
        "m2.toml",
        "[time]\nframes = 3\nloop = true\n[morph]\nsource = \"a.toml\"\ntarget = \"a.toml\"\n",
    );
    assert_bad(
        &pdeshape(&["animate", s(&m2), "-o", s(&glb)]),
        &["m2.toml", "time.loop"],
    );
    // A morph of a design with itself is fine.
    let m3 = write(
        dir.path(),
        "m3.toml",
        "[time]\nframes = 3\n[morph]\nsource = \"a.toml\"\ntarget = \"a.toml\"\n",
    );
    let o = pdeshape(&["animate", s(&m3), "-o", s(&glb)]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", &timed());
    let p = |n: &str| dir.path().join(n);
    let cases: [(Vec<String>, &[&str]); 4] = [
        (vec!["-o".into(), s(&p("a.obj")).into()], &["-o", ".glb"]),
        (
            vec![
                "-o".into(),
                s(&p("a.glb")).into(),
                "--csv".into(),
                s(&p("m.txt")).into(),
            ],
            &["--csv", ".csv"],
        ),
        (
            vec![
                "-o".into(),
                s(&p("a.glb")).into(),
                "--plot".into(),
                s(&p("m.png")).into(),
            ],
            &["--plot", ".svg"],
        ),
        (
            vec![
                "-o".into(),
                s(&p("a.glb")).into(),
                "--scale".into(),
                "0".into(),
            ],
            &["--scale", "positive"],
        ),
    ];
    for (extra, needles) in cases {
        let mut args = vec!["animate".to_string(), s(&d).to_string()];
        args.extend(extra);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_bad(&pdeshape(&refs), needles);
    }
    assert_eq!(files(dir.path()), ["d.toml"]);
    // --scale multiplies the positions: the file's bounds grow with it.
    let glb = |k: &str| {
        let out = p(&format!("s{k}.glb"));
        let o = pdeshape(&[
            "animate",
            s(&d),
            "-o",
            s(&out),
            "--nu",
            "6",
            "--nv",
            "8",
            "--scale",
            k,
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read(out).unwrap().len()
    };
    assert_eq!(glb("1"), glb("2"), "scaling keeps the layout");
}

#[test]
fn surface_at_a_time_is_the_design_with_the_formulas_evaluated() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", &timed());
    let fixed = write(
        dir.path(),
        "f.toml",
        &timed().replace("\"= 1.5 + 0.5*t\"", "1.75"),
    );
    let (a, b) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
    let o = pdeshape(&["surface", s(&d), "--time", "0.5", "-o", s(&a)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = pdeshape(&["surface", s(&fixed), "-o", s(&b)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let o = pdeshape(&["surface", s(&d), "--time", "0.25", "-o", s(&b)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

/// A design with a `[rig]` and a bad value: the message names the value, not `[rig]` (which only
/// the timed reader knows).
#[test]
fn errors_of_a_rigged_design_name_the_bad_value() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("a.glb");
    let arm = std::fs::read_to_string(example_path("anim/arm.toml")).unwrap();
    let cases: [(&str, &str, &[&str]); 2] = [
        ("end = 2.0\n", "end = -1.0\n", &["d.toml:", "time.end"]),
        (
            "joint\naxis = [0.0, 1.0, 0.0]",
            "joint\naxis = [0.0, 0.0, 0.0]",
            &["d.toml:", "rig.bones[0].axis"],
        ),
    ];
    for (from, to, needles) in cases {
        let d = write(dir.path(), "d.toml", &edit(&arm, from, to));
        for args in [vec!["check", s(&d)], vec!["animate", s(&d), "-o", s(&glb)]] {
            let o = pdeshape(&args);
            assert_bad(&o, needles);
            assert!(!stderr(&o).contains("unknown field"), "{}", stderr(&o));
        }
        assert!(!glb.exists());
    }
}
