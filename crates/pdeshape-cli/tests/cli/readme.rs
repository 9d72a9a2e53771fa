//! The README's commands: every command of a `sh` code block runs as written and succeeds, in a
//! scratch directory that sees the bundled `examples/`, with the built `pdeshape` first on the
//! `PATH`. A block whose fence reads `sh needs: <what>` (a toolchain, a browser, Python) is not
//! run here; each of its commands must be one the CI runs (the marker names why it cannot run
//! inside the test suite, not a way around it).

use crate::common::*;

/// A fenced code block: its info string (after the backticks) and its lines.
struct Block {
    info: String,
    line: usize,
    lines: Vec<String>,
}

fn blocks(text: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (k, l) in text.lines().enumerate() {
        let t = l.trim_start();
        if let Some(info) = t.strip_prefix("```") {
            match open.take() {
                Some(b) => out.push(b),
                None => {
                    open = Some(Block {
                        info: info.trim().to_string(),
                        line: k + 1,
                        lines: Vec::new(),
                    })
                }
            }
        } else if let Some(b) = open.as_mut() {
            b.lines.push(l.to_string());
        }
    }
    assert!(open.is_none(), "a code block is not closed");
    out
}

/// The commands of a shell block: continuation lines (`\` at the end) joined, blank lines and
/// comment lines dropped.
fn commands(b: &Block) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for l in &b.lines {
        let t = l.trim();
        if cur.is_empty() && (t.is_empty() || t.starts_with('#')) {
            continue;
        }
        match t.strip_suffix('\\') {
            Some(head) => {
                cur.push_str(head.trim_end());
                cur.push(' ');
            }
            None => {
                cur.push_str(t);
                out.push(std::mem::take(&mut cur));
            }
        }
    }
    out
}

/// Why a command that needs something the test suite does not have is still checked: it is
/// one the CI runs.
fn run_by_ci(command: &str, root: &Path) -> Result<(), String> {
    let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap_or_default();
    let words: Vec<&str> = command.split_whitespace().collect();
    match words.as_slice() {
        ["cargo", "test", "--workspace", "--release"] => read(".ci/run")
            .lines()
            .any(|l| l.trim() == command)
            .then_some(())
            .ok_or_else(|| ".ci/run does not run it".to_string()),
        ["cargo", "install", "--locked", "--path", path] => read(&format!("{path}/Cargo.toml"))
            .contains("name = \"pdeshape\"")
            .then_some(())
            .ok_or_else(|| format!("{path} is not the crate of the pdeshape binary")),
        ["pip", "install", .., path] if path.starts_with("./") => {
            let ok = root.join(path).join("pyproject.toml").exists()
                && read(".ci/python.sh").contains(&format!(" {path}\n"));
            ok.then_some(())
                .ok_or_else(|| format!("{path} is not the package .ci/python.sh installs"))
        }
        ["pdeshape", "serve", ..] => read("e2e/harness.mjs")
            .contains("'serve'")
            .then_some(())
            .ok_or_else(|| "the end-to-end harness does not start serve".to_string()),
        _ => Err("not a command the CI runs".to_string()),
    }
}

#[test]
fn readme_commands_run() {
    let root = examples_dir().parent().unwrap().to_path_buf();
    let text = std::fs::read_to_string(root.join("README.md")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(root.join("examples"), dir.path().join("examples")).unwrap();
    let bin = Path::new(env!("CARGO_BIN_EXE_pdeshape")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let (mut ran, mut checked) = (0, 0);
    for b in blocks(&text) {
        let Some(rest) = b.info.strip_prefix("sh") else {
            continue;
        };
        let rest = rest.trim();
        if let Some(need) = rest.strip_prefix("needs:") {
            assert!(
                !need.trim().is_empty(),
                "README line {}: needs what?",
                b.line
            );
            for c in commands(&b) {
                run_by_ci(&c, &root).unwrap_or_else(|e| panic!("README line {}: {c}: {e}", b.line));
                checked += 1;
            }
            continue;
        }
        assert!(
            rest.is_empty(),
            "README line {}: unknown marker '{rest}'",
            b.line
        );
        for c in commands(&b) {
            let out = Command::new("sh")
                .arg("-c")
                .arg(&c)
                .current_dir(dir.path())
                .env("PATH", &path)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "README line {}: {c}: {}",
                b.line,
                String::from_utf8_lossy(&out.stderr)
            );
            ran += 1;
        }
    }
    assert!(
        ran >= 5 && checked >= 4,
        "{ran} commands run, {checked} checked"
    );
    // What the commands were to make is there.
    for f in ["cup.obj", "cup.png", "cup_fit.toml", "cup_fit.stl"] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
}

/// The marker is honoured and nothing else: a command that is not the CI's is refused even when
/// its block is marked.
#[test]
fn readme_markers_are_not_an_escape() {
    let root = examples_dir().parent().unwrap().to_path_buf();
    assert!(run_by_ci("cargo test --workspace --release", &root).is_ok());
    assert!(run_by_ci("cargo install --locked --path crates/pdeshape-cli", &root).is_ok());
    assert!(run_by_ci("cargo install --locked --path crates/geometry", &root).is_err());
    // Without --locked, cargo install ignores Cargo.lock and takes the newest versions.
    assert!(run_by_ci("cargo install --path crates/pdeshape-cli", &root).is_err());
    assert!(run_by_ci("cargo test --workspace", &root).is_err());
    assert!(run_by_ci("rm -rf examples", &root).is_err());
    let b = blocks("```sh needs: x\na \\\n  b\n# c\n\nd\n```\n");
    assert_eq!(b.len(), 1);
    assert_eq!(commands(&b[0]), vec!["a b".to_string(), "d".to_string()]);
}
