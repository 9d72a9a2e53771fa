//! The edges of the operating system seen from the binary: a signal between the outputs of one
//! command (all or none of them written), device nodes as outputs.

use crate::common::*;
use std::os::unix::fs::MetadataExt;
use std::time::{Duration, Instant};

/// The optimiser's small design (two circles, a few evaluations): its outputs are the design
/// file, a large mesh (at the grid the test asks for), a picture and the search log.
const SEARCH: &str = r#"title = "optimise me"
conditions = [
  { u = 0.0, curve = "p1" },
  { u = 0.0, derivative = 1, curve = "t1" },
  { u = 1.0, curve = "p2" },
  { u = 1.0, derivative = 1, curve = "t2" },
]

[operator]
kind = "polyharmonic"
order = 2
a = 1.0

[solver]
modes = 2

[curves.p1]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0
[curves.d1]
type = "circle"
center = [0.0, 0.0, 0.5]
radius = 1.5
[curves.t1]
type = "derivative"
position = "p1"
direction = "d1"
[curves.p2]
type = "circle"
center = [0.0, 0.0, 2.0]
radius = 0.7
[curves.d2]
type = "circle"
center = [0.0, 0.0, 2.5]
radius = 0.7
[curves.t2]
type = "derivative"
position = "p2"
direction = "d2"

[optimize]
objective = "bending"
evaluations = 4
chains = 1
polish = 0
parameters = [
  { name = "d1Dx", min = 0.2, max = 2.0 },
  { name = "a", min = 0.3, max = 3.0 },
]
"#;

/// The inode of `p`, if it exists.
fn inode(p: &Path) -> Option<u64> {
    std::fs::symlink_metadata(p).ok().map(|m| m.ino())
}

/// A signal that arrives once the first output of `optimize` is in place (the design file
/// `best.toml`, which existed before the run, replaced) finds the other outputs either all in
/// place too or undone with it: `best.toml` is the old file again and no other output exists.
/// The mesh is large (700 × 700 grid, about 80 MB), so a run that renames its outputs one by
/// one with the mesh's sync in between is caught between them.
#[cfg(unix)]
#[test]
fn a_signal_between_outputs_leaves_all_of_them_or_none() {
    let dir = tempfile::tempdir().unwrap();
    let design = write(dir.path(), "d.toml", SEARCH);
    let best = dir.path().join("best.toml");
    let others = ["best.obj", "best.png", "best.csv"].map(|n| dir.path().join(n));
    for signal in ["-TERM", "-HUP", "-INT"] {
        std::fs::write(&best, "# the previous best\n").unwrap();
        for o in &others {
            let _ = std::fs::remove_file(o);
        }
        let before = inode(&best);
        let child = Command::new(env!("CARGO_BIN_EXE_pdeshape"))
            .args([
                "optimize",
                s(&design),
                "-o",
                s(&best),
                "--nu",
                "700",
                "--nv",
                "700",
            ])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Wait until the first output is in place, then stop the run.
        let start = Instant::now();
        while inode(&best) == before {
            assert!(
                start.elapsed() < Duration::from_secs(120),
                "{signal}: the design file was never replaced"
            );
            std::thread::sleep(Duration::from_millis(1));
        }
        let pid = child.id().to_string();
        let _ = Command::new("kill").args([signal, &pid]).status();
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        let text = std::fs::read_to_string(&best).unwrap();
        let present: Vec<bool> = others.iter().map(|o| o.exists()).collect();
        if text == "# the previous best\n" {
            // Undone: nothing of the run is left, and the message says so.
            assert_eq!(present, [false; 3], "{signal}: partial outputs; {stderr}");
            assert_eq!(out.status.code(), Some(130), "{signal}: {stderr}");
            assert!(
                stderr.contains("interrupted; no output file was written"),
                "{signal}: {stderr}"
            );
            assert!(!stdout.contains("wrote"), "{signal}: {stdout}");
        } else {
            // Completed: every output is there, and no message denies it.
            assert!(text.contains("optimise me"), "{signal}: {text}");
            assert_eq!(present, [true; 3], "{signal}: partial outputs; {stderr}");
            assert!(
                !stderr.contains("no output file was written"),
                "{signal}: {stderr}"
            );
        }
        let left: Vec<String> = files(dir.path())
            .into_iter()
            .filter(|f| f.contains(".pdeshape-"))
            .collect();
        assert!(left.is_empty(), "{signal}: left {left:?}");
    }
}

/// Makes a character device node at `path` like `/dev/null` (1, 3) or `/dev/zero` (1, 5) with
/// `mknod`; where that is not permitted, a Unix socket (another kind of special file the same
/// check refuses). Returns the words the refusal uses for what was made.
#[cfg(unix)]
fn special_file(path: &Path, minor: u32) -> &'static str {
    let made = Command::new("mknod")
        .arg(path)
        .args(["c", "1", &minor.to_string()])
        .status()
        .is_ok_and(|s| s.success());
    if made {
        "a device"
    } else {
        eprintln!("mknod is not permitted here: a Unix socket stands in for the device");
        let listener = std::os::unix::net::UnixListener::bind(path).unwrap();
        std::mem::forget(listener);
        "a socket"
    }
}

/// A device node as an output (made with mknod in a temporary directory, never the real
/// `/dev` entries) is refused before any work and left a device; as an input (a `/dev/zero`
/// twin) it is refused, not read without end.
#[cfg(unix)]
#[test]
fn device_nodes_are_refused_as_outputs_and_inputs() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let design = example_path("cup.toml");
    for (name, args) in [
        ("null.obj", vec!["surface", s(&design), "-o"]),
        ("null.stp", vec!["surface", s(&design), "-o"]),
        ("null.png", vec!["render", s(&design), "-o"]),
    ] {
        let node = dir.path().join(name);
        let what = special_file(&node, 3);
        let mut args = args.clone();
        args.push(s(&node));
        let start = Instant::now();
        let out = pdeshape(&args);
        assert_bad(&out, &[name, what, "not a regular file"]);
        assert!(start.elapsed() < Duration::from_secs(10));
        let t = std::fs::symlink_metadata(&node).unwrap().file_type();
        assert!(t.is_char_device() || t.is_socket(), "{args:?}: replaced");
    }
    let zero = dir.path().join("zero.toml");
    special_file(&zero, 5);
    let start = Instant::now();
    let out = pdeshape(&["check", s(&zero)]);
    assert_bad(&out, &["zero.toml"]);
    assert!(start.elapsed() < Duration::from_secs(10));
}

/// `animate --retarget` prices its closest-point searches before the first one: a mesh of
/// 300 000 vertices on the ventricle's four surfaces (1 200 000 searches, about 9 s of work,
/// more than a minute of CPU before) is refused at once with one line.
#[test]
fn retargeting_a_huge_mesh_is_refused_from_its_cost() {
    let dir = tempfile::tempdir().unwrap();
    let mut obj = String::new();
    let n = 300_000;
    for i in 0..n {
        let a = i as f64 * 0.001;
        obj += &format!(
            "v {} {} {}\n",
            2.6 * a.cos(),
            2.6 * a.sin(),
            1.0 + (i % 800) as f64 * 0.01
        );
    }
    for i in (0..n - 2).step_by(3) {
        obj += &format!("f {} {} {}\n", i + 1, i + 2, i + 3);
    }
    let mesh = write(dir.path(), "scan.obj", &obj);
    let v = example_path("anim/ventricle.toml");
    let glb = dir.path().join("out.glb");
    let moved = dir.path().join("moved.glb");
    let start = Instant::now();
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
        s(&moved),
    ]);
    assert_bad(
        &out,
        &[
            "--retarget",
            "vertices",
            "closest-point searches",
            "decimate",
        ],
    );
    assert!(start.elapsed() < Duration::from_secs(10));
    assert_eq!(files(dir.path()), ["scan.obj"]);
}

/// Counts read from an IGES file (control points, degrees) are checked against the parameters
/// the entity has before anything is sized from them; a PLY header's element counts against
/// the bytes of the file.
#[test]
fn counts_read_from_files_are_checked_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let design = example_path("cup.toml");
    let igs = dir.path().join("cup.igs");
    assert!(pdeshape(&["--quiet", "surface", s(&design), "-o", s(&igs)])
        .status
        .success());
    let text = std::fs::read_to_string(&igs).unwrap();
    // The first parameter line of an entity 128: `128,K1,K2,M1,M2,…`.
    let line = text
        .lines()
        .find(|l| l.starts_with("128,") && l.as_bytes().get(72) == Some(&b'P'))
        .unwrap();
    let fields: Vec<&str> = line[..64].split(',').collect();
    for (k1, m1) in [
        ("99999999999", fields[3]),
        ("18446744073709551615", fields[3]),
        (fields[1], "4000000000"),
    ] {
        // The rest of the line's parameters are dropped: the counts alone must be refused.
        let head = format!("128,{k1},{},{m1},{},", fields[2], fields[4]);
        let new = format!("{head:<64}{}", &line[64..]);
        let bad = write(dir.path(), "bad.igs", &text.replacen(line, &new, 1));
        let out = pdeshape(&["roundtrip", s(&design), s(&bad)]);
        assert_bad(&out, &["bad.igs", "do not fit in the", "parameters"]);
    }
    // A PLY header announcing a hundred thousand vertices in a file of a few hundred bytes.
    let ply = "ply\nformat ascii 1.0\nelement vertex 100000\nproperty float x\nproperty float y\n\
               property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
               0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let mesh = write(dir.path(), "m.ply", ply);
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&dir.path().join("fit.toml"))]);
    assert_bad(&out, &["m.ply", "100000 vertex elements", "bytes can hold"]);
}

/// Messages print each place once, say what the facts are, and show numbers short: a radius of
/// 1e300 makes the solution non-finite (not "ill-conditioned" with a condition number of 43),
/// at `patches[0].conditions[0]` (not `patches[0].conditions.conditions[0]`); no number in any
/// error of a design with one value set to 1e308 or 1e-308 is printed with its hundreds of
/// digits.
#[test]
fn messages_place_once_say_the_facts_and_show_numbers_short() {
    let dir = tempfile::tempdir().unwrap();
    let cup = example("cup.toml");
    let huge = cup.replacen("radius = 1.0", "radius = 1e300", 1);
    assert_ne!(huge, cup);
    let f = write(dir.path(), "huge.toml", &huge);
    let line = assert_bad(
        &pdeshape(&["check", s(&f)]),
        &["patches[0].conditions[0]: ", "not finite"],
    );
    assert!(!line.contains("conditions.conditions"), "{line}");
    assert!(!line.contains("ill-conditioned"), "{line}");
    let long_digits = |l: &str| {
        l.split(|c: char| !c.is_ascii_digit())
            .any(|run| run.len() > 17)
    };
    for name in ["aeroplane.toml", "cup.toml"] {
        let text = example(name);
        let spans: Vec<(usize, usize)> = text
            .match_indices(|c: char| c.is_ascii_digit())
            .map(|(i, _)| i)
            .filter(|&i| {
                i == 0
                    || !text.as_bytes()[i - 1].is_ascii_alphanumeric()
                        && text.as_bytes()[i - 1] != b'.'
            })
            .map(|i| {
                let end = text[i..]
                    .find(|c: char| !(c.is_ascii_digit() || c == '.'))
                    .map_or(text.len(), |k| i + k);
                (i, end)
            })
            .take(40)
            .collect();
        for (a, b) in spans {
            for v in ["1e308", "1e-308"] {
                let m = format!("{}{v}{}", &text[..a], &text[b..]);
                let f = write(dir.path(), "m.toml", &m);
                let out = pdeshape(&["check", s(&f)]);
                let err = String::from_utf8_lossy(&out.stderr);
                assert!(!long_digits(&err), "{name} with {v} at byte {a}: {err}");
            }
        }
    }
}

/// `--quiet` silences the "wrote" line of a picture of a trimmed design too, and the line is
/// printed once the picture is in place when it is not quiet.
#[test]
fn quiet_silences_the_picture_of_a_trimmed_design() {
    let dir = tempfile::tempdir().unwrap();
    let design = example_path("trimmed_vase.toml");
    let png = dir.path().join("vase.png");
    let args = ["render", s(&design), "-o", s(&png), "--size", "64x48"];
    let loud = pdeshape(&args);
    assert!(loud.status.success());
    assert!(String::from_utf8_lossy(&loud.stdout).starts_with("wrote "));
    let mut quiet = vec!["--quiet"];
    quiet.extend(args);
    let out = pdeshape(&quiet);
    assert!(out.status.success());
    assert!(out.stdout.is_empty() && out.stderr.is_empty(), "{out:?}");
    assert!(png.exists());
}
