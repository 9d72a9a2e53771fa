//! Flags that do not apply, or whose values are out of range, for render, curve, optimize, fit,
//! analyze, animate and the CAD outputs (`surface` to STEP/IGES, `roundtrip`): each is refused
//! with one line naming the flag, exit status 2, and nothing is written (the flags of `surface`
//! to meshes and of `blend` are in `robust.rs`).

use crate::common::*;

/// A closed octahedron, a mesh `fit` reads.
const OCTAHEDRON: &str = "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

/// Runs every case in a directory holding the inputs; each must fail with status 2 and one
/// line containing its needles, and the directory must hold only the inputs afterwards.
fn refused(cases: &[(&[&str], &[&str])]) {
    let dir = tempfile::tempdir().unwrap();
    let inputs = [
        ("cup.toml", example("cup.toml")),
        ("dyn.toml", example("dynamic_section33.toml")),
        ("opt.toml", example("optimize_curvature.toml")),
        ("vase.toml", example("trimmed_vase.toml")),
        ("arm.toml", example("anim/arm.toml")),
        ("octahedron.obj", OCTAHEDRON.to_string()),
    ];
    for (name, text) in &inputs {
        write(dir.path(), name, text);
    }
    let mut expected: Vec<String> = inputs.iter().map(|(n, _)| n.to_string()).collect();
    expected.sort();
    for (args, needles) in cases {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_pdeshape"))
            .current_dir(dir.path())
            .args(*args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(
            out.status.code(),
            Some(2),
            "{args:?}: status {:?}, stderr {stderr}",
            out.status
        );
        let line = assert_bad(&out, needles);
        assert!(line.len() < 300, "{args:?}: {line}");
        assert_eq!(files(dir.path()), expected, "{args:?} left files");
    }
}

#[test]
fn render_flags() {
    refused(&[
        (
            &["render", "cup.toml", "-o", "x.png", "--range", "-1,1"],
            &["--range: needs --color gauss, mean or shear"],
        ),
        (
            &["render", "vase.toml", "-o", "x.png", "--color", "gauss"],
            &["--color: colours are not drawn on trimmed designs"],
        ),
        (
            &["render", "cup.toml", "-o", "x.jpg"],
            &["-o x.jpg: the picture must be a .png file"],
        ),
        (
            &["render", "cup.toml", "-o", "x.png", "--size", "0x10"],
            &["--size", "between 1 and"],
        ),
        (
            &["render", "cup.toml", "-o", "x.png", "--view", "0,0,0"],
            &["--view: must not be the zero vector"],
        ),
        (&["render", "cup.toml", "-o", "x.png", "--nu", "1"], &["nu"]),
    ]);
}

#[test]
fn curve_flags() {
    refused(&[
        (
            &["curve", "dyn.toml", "-o", "x.txt"],
            &["-o x.txt: must end in .csv"],
        ),
        (
            &["curve", "dyn.toml", "-o", "x.csv", "--frames", "f.txt"],
            &["--frames f.txt: must end in .csv"],
        ),
        (
            &["curve", "dyn.toml", "-o", "x.csv", "--picture", "p.png"],
            &["--picture p.png: must end in .svg"],
        ),
        (
            &["curve", "cup.toml", "-o", "x.csv"],
            &["cup.toml", "no [dynamic] section"],
        ),
    ]);
}

#[test]
fn optimize_flags() {
    refused(&[
        (
            &["optimize", "opt.toml", "-o", "x.obj"],
            &["-o x.obj: the optimised design file must end in .toml"],
        ),
        (
            &["optimize", "opt.toml", "-o", "x.toml", "--threads", "0"],
            &["--threads: must be at least 1"],
        ),
        (
            &[
                "optimize",
                "opt.toml",
                "-o",
                "x.toml",
                "--threads",
                "99999999",
            ],
            &["--threads: at most 1024 worker threads (got 99999999)"],
        ),
        (
            &[
                "optimize",
                "opt.toml",
                "-o",
                "x.toml",
                "--evaluations",
                "99999999999",
            ],
            &["--evaluations", "99999999999"],
        ),
        (
            &[
                "optimize",
                "opt.toml",
                "-o",
                "x.toml",
                "--polish",
                "99999999999",
            ],
            &["--polish", "99999999999"],
        ),
        (
            &["optimize", "opt.toml", "-o", "x.toml", "--chains", "0"],
            &["--chains"],
        ),
        (
            &["optimize", "cup.toml", "-o", "x.toml"],
            &["cup.toml", "optimize", "no [optimize] section"],
        ),
        (
            &["optimize", "opt.toml", "-o", "opt.toml"],
            &["would overwrite the design file"],
        ),
    ]);
}

#[test]
fn fit_flags() {
    refused(&[
        (
            &[
                "fit",
                "octahedron.obj",
                "-o",
                "x.toml",
                "--template",
                "cup.toml",
            ],
            // A design file is not a template: refused at its first foreign key.
            &["cup.toml:", "unknown key (expected one of: a, parts)"],
        ),
        (
            &["fit", "octahedron.obj", "-o", "x.toml", "--tolerance", "0"],
            &["--tolerance 0: must be a number between 0 and 1"],
        ),
        (
            &["fit", "octahedron.obj", "-o", "x.obj"],
            &["-o x.obj: the file name must end in .toml"],
        ),
        (
            &["fit", "octahedron.obj", "-o", "x.toml", "--json", "x.txt"],
            &["--json x.txt: the file name must end in .json"],
        ),
        (
            &[
                "fit",
                "octahedron.obj",
                "-o",
                "x.toml",
                "--picture",
                "x.jpg",
            ],
            &["--picture x.jpg: the file name must end in .png"],
        ),
        (
            &["fit", "cup.toml", "-o", "x.toml"],
            &["cup.toml: unknown mesh format"],
        ),
    ]);
}

#[test]
fn analyze_flags() {
    refused(&[
        (
            &["analyze", "cup.toml", "--tolerance", "0"],
            &["--tolerance: must be positive and below 1 (got 0)"],
        ),
        (
            &["analyze", "cup.toml", "--tolerance", "1"],
            &["--tolerance: must be positive and below 1 (got 1)"],
        ),
        (
            &["analyze", "cup.toml", "--tolerance", "NaN"],
            &["--tolerance: must be positive and below 1"],
        ),
    ]);
}

#[test]
fn animate_flags() {
    refused(&[
        (
            &["animate", "arm.toml", "-o", "x.gltf"],
            &["-o x.gltf: must end in .glb"],
        ),
        (
            &["animate", "arm.toml", "-o", "x.glb", "--csv", "m.txt"],
            &["--csv m.txt: must end in .csv"],
        ),
        (
            &["animate", "arm.toml", "-o", "x.glb", "--plot", "m.png"],
            &["--plot m.png: must end in .svg"],
        ),
        (
            &["animate", "arm.toml", "-o", "x.glb", "--scale", "0"],
            &["--scale: must be finite and positive"],
        ),
        // Size and view only apply to the pictures of --apng, --gif and --contact-sheet.
        (
            &["animate", "arm.toml", "-o", "x.glb", "--view", "1,0,0"],
            &["--view: applies only to the pictures of --apng, --gif and --contact-sheet"],
        ),
        (
            &[
                "animate",
                "arm.toml",
                "-o",
                "x.glb",
                "--frames-dir",
                "frames",
                "--picture-size",
                "100x100",
            ],
            &["--picture-size: applies only to the pictures of --apng, --gif and --contact-sheet"],
        ),
        (
            &[
                "animate",
                "arm.toml",
                "-o",
                "x.glb",
                "--retarget",
                "octahedron.obj",
            ],
            &["--retarget: give --retarget-output"],
        ),
        (
            &[
                "animate",
                "arm.toml",
                "-o",
                "x.glb",
                "--retarget-output",
                "r.glb",
            ],
            &["--retarget-output: give --retarget MESH"],
        ),
        (
            &["animate", "arm.toml", "-o", "x.glb", "--apng", "a.gif"],
            &["--apng a.gif: must end in .png"],
        ),
        (
            &[
                "animate",
                "arm.toml",
                "-o",
                "x.glb",
                "--contact-sheet",
                "c.png",
                "--picture-size",
                "0x0",
            ],
            &["--picture-size"],
        ),
    ]);
}

#[test]
fn cad_flags() {
    refused(&[
        (
            &["surface", "cup.toml", "-o", "x.step", "--separate-patches"],
            &["--separate-patches: does not apply to STEP or IGES output"],
        ),
        (
            &["surface", "cup.toml", "-o", "x.igs", "--nv", "9"],
            &["--nv: does not apply to STEP or IGES output"],
        ),
        (
            &["surface", "cup.toml", "-o", "x.step", "--tolerance=-1"],
            &["--tolerance: must be a positive number (got -1)"],
        ),
        (
            &["surface", "cup.toml", "-o", "x.step", "--units", "furlong"],
            &["--units"],
        ),
        (
            &["roundtrip", "cup.toml", "x.step", "--tolerance=-1"],
            &["--tolerance: must be a positive number (got -1)"],
        ),
        (
            &["roundtrip", "cup.toml", "x.step", "--tolerance", "NaN"],
            &["--tolerance: must be a positive number (got NaN)"],
        ),
        (
            &["roundtrip", "cup.toml", "x.txt"],
            &["x.txt: not a STEP or IGES file name"],
        ),
    ]);
}

/// The size and view of the animation's pictures are taken when a picture output is given.
#[test]
fn animate_takes_size_and_view_with_a_picture_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "arm.toml", &example("anim/arm.toml"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .current_dir(dir.path())
        .args([
            "animate",
            s(&d),
            "-o",
            "x.glb",
            "--nu",
            "8",
            "--nv",
            "12",
            "--contact-sheet",
            "c.png",
            "--picture-size",
            "64x48",
            "--view",
            "1,0,0",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("c.png").exists());
}

/// CSV of a trimmed design is refused with what trims it: the `[[trims]]` entry, or the
/// attachment (the `on_patch` curve and the host patch) that implies the hole.
#[test]
fn csv_of_a_trimmed_design_names_what_trims_it() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "teacup.toml", &example("teacup.toml"));
    write(dir.path(), "vase.toml", &example("trimmed_vase.toml"));
    let cases: [(&str, &[&str]); 2] = [
        (
            "teacup.toml",
            &[
                "-o x.csv",
                "on_patch curve curves.",
                "_root cuts its hole in 'bowl'",
                "attachment",
            ],
        ),
        (
            "vase.toml",
            &["-o x.csv", "[[trims]] (trims[0] cuts holes in 'wall')"],
        ),
    ];
    for (design, needles) in cases {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_pdeshape"))
            .current_dir(dir.path())
            .args(["surface", design, "-o", "x.csv"])
            .output()
            .unwrap();
        assert_bad(&out, needles);
        assert!(!dir.path().join("x.csv").exists());
    }
}
