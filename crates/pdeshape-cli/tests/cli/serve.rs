//! `pdeshape serve` as a process: refused starts exit 2 with one line; a running server answers
//! over TCP and stops cleanly on Ctrl-C (SIGINT).

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};

fn pdeshape() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pdeshape"))
}

#[test]
fn refused_starts_exit_2_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    for (args, needle) in [
        (vec!["serve", "missing.toml"], "missing.toml"),
        (vec!["serve", "../x.toml"], "'..'"),
        (vec!["serve", "/etc/x.toml"], "relative"),
        (vec!["serve", "--host", "nonsense"], "--host"),
    ] {
        let out = pdeshape()
            .args(&args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("error: ") && err.contains(needle),
            "{args:?}: {err}"
        );
    }
}

#[cfg(unix)]
#[test]
fn serves_over_tcp_and_stops_on_ctrl_c() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = pdeshape()
        .args(["serve", "--port", "0"])
        .current_dir(dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    // pdeshape designer: http://127.0.0.1:PORT/?token=TOKEN
    let url = line.trim().rsplit(' ').next().unwrap().to_string();
    let rest = url.strip_prefix("http://").unwrap();
    let (host, query) = rest.split_once('/').unwrap();
    let token = query.strip_prefix("?token=").unwrap();
    assert_eq!(token.len(), 32);
    assert!(host.starts_with("127.0.0.1:"));
    let get = |path: &str, token: &str| {
        let mut s = std::net::TcpStream::connect(host).unwrap();
        write!(
            s,
            "GET {path} HTTP/1.1\r\nHost: {host}\r\nx-pdeshape-token: {token}\r\nConnection: close\r\n\r\n"
        )
        .unwrap();
        let mut answer = Vec::new();
        s.read_to_end(&mut answer).unwrap();
        String::from_utf8_lossy(&answer).into_owned()
    };
    assert!(get("/api/files", token).starts_with("HTTP/1.1 200"));
    assert!(get("/api/files", "nope").starts_with("HTTP/1.1 403"));
    assert!(get(&format!("/?token={token}"), "").starts_with("HTTP/1.1 200"));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&out.stderr).contains("stopping"));
}
