//! Helpers shared by the end-to-end tests of the `pdeshape` binary.
#![allow(dead_code)]

pub(crate) use std::path::{Path, PathBuf};
pub(crate) use std::process::{Command, Output};

pub(crate) use pdeshape_testkit::{example, example_path, examples_dir};

/// A biharmonic design that is valid; the bad cases of the tests each break one thing in it.
pub(crate) use pdeshape_testkit::designs::BIHARMONIC as GOOD;

pub(crate) fn pdeshape(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .args(args)
        .output()
        .expect("the pdeshape binary runs")
}

pub(crate) fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Replaces exactly one occurrence of `from` in `text`.
pub(crate) fn edit(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "'{from}' must occur once");
    text.replace(from, to)
}

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Status 2, exactly one stderr line `error: …` containing every `needle`, nothing on stdout.
pub(crate) fn assert_bad(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "one line expected on stderr, got: {stderr}");
    assert!(lines[0].starts_with("error: "), "{stderr}");
    for n in needles {
        assert!(lines[0].contains(n), "'{n}' not in: {stderr}");
    }
    assert!(
        out.stdout.is_empty(),
        "stdout: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    lines[0].to_string()
}

/// The files in `dir` (names), to check that nothing was left behind.
pub(crate) fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// Runs `surface` on a design text that is bad; checks the error and that no output (and no
/// temporary file) exists afterwards.
pub(crate) fn bad_design(text: &str, needles: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let d = write(dir.path(), "d.toml", text);
    let out_path = dir.path().join("out.obj");
    let out = pdeshape(&["surface", s(&d), "-o", s(&out_path)]);
    let line = assert_bad(&out, needles);
    assert!(!out_path.exists());
    assert_eq!(files(dir.path()), vec!["d.toml".to_string()]);
    // `check` reports the same error.
    let out = pdeshape(&["check", s(&d)]);
    assert_eq!(assert_bad(&out, needles), line);
    line
}
