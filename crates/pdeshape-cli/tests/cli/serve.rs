//! `pdeshape serve` as a process: refused starts exit 2 with one line; a running server answers
//! over TCP and stops cleanly on Ctrl-C (SIGINT).

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Command, Stdio};

fn pdeshape() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pdeshape"))
}

#[test]
fn refused_starts_exit_2_with_one_line() {
    // Started one level inside a directory of its own, so that `../x.toml` names a file that
    // does not exist (an existing design anywhere is served from its own directory).
    let top = tempfile::tempdir().unwrap();
    let dir = top.path().join("start");
    std::fs::create_dir(&dir).unwrap();
    for (args, needle) in [
        (vec!["serve", "missing.toml"], "missing.toml"),
        (vec!["serve", "../x.toml"], "'..'"),
        (vec!["serve", "/etc/x.toml"], "relative"),
        (vec!["serve", "--host", "nonsense"], "--host"),
    ] {
        let out = pdeshape().args(&args).current_dir(&dir).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("error: ") && err.contains(needle),
            "{args:?}: {err}"
        );
        // The system's words, without Rust's "(os error N)".
        assert!(!err.contains("os error"), "{args:?}: {err}");
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

/// A running `pdeshape serve` in a temporary directory: its process, address and token.
struct Server {
    child: std::process::Child,
    host: String,
    token: String,
    dir: tempfile::TempDir,
}

impl Server {
    fn start(prepare: impl FnOnce(&std::path::Path)) -> Server {
        Server::start_with(&[], prepare)
    }

    /// [`Server::start`] with more arguments after `serve --port 0`.
    fn start_with(args: &[&str], prepare: impl FnOnce(&std::path::Path)) -> Server {
        let dir = tempfile::tempdir().unwrap();
        prepare(dir.path());
        let mut child = pdeshape()
            .args(["serve", "--port", "0"])
            .args(args)
            .current_dir(dir.path())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let url = line.trim().rsplit(' ').next().unwrap().to_string();
        let (host, query) = url
            .strip_prefix("http://")
            .unwrap()
            .split_once('/')
            .unwrap();
        Server {
            host: host.to_string(),
            token: query.strip_prefix("?token=").unwrap().to_string(),
            child,
            dir,
        }
    }

    /// One request on a connection of its own; the whole answer (`None`: the connection was
    /// reset or closed before an answer).
    fn request(&self, method: &str, path: &str, body: &[u8]) -> Option<String> {
        let mut s = std::net::TcpStream::connect(&self.host).unwrap();
        s.set_read_timeout(Some(std::time::Duration::from_secs(30)))
            .unwrap();
        let head = format!(
            "{method} {path} HTTP/1.1\r\nHost: {}\r\nx-pdeshape-token: {}\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
            self.host,
            self.token,
            body.len()
        );
        s.write_all(head.as_bytes()).ok()?;
        s.write_all(body).ok()?;
        let mut answer = Vec::new();
        s.read_to_end(&mut answer).ok()?;
        (!answer.is_empty()).then(|| String::from_utf8_lossy(&answer).into_owned())
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The status and the JSON message of an answer.
fn status_and_error(answer: &str) -> (u16, String) {
    let status = answer[9..12].parse().unwrap();
    let body = answer.split_once("\r\n\r\n").map_or("", |(_, b)| b);
    let json: serde_json::Value =
        serde_json::from_str(body).unwrap_or_else(|_| panic!("the body is not JSON: {answer}"));
    (status, json["error"].as_str().unwrap_or("").to_string())
}

/// Saves the server refuses (a read-only file, a file in a read-only folder, a name longer than
/// the file system takes)
/// answer a 4xx with one line naming the file relative to the start directory: never 500,
/// never the server's own path, never the CLI's `--force`.
#[cfg(unix)]
#[test]
fn refused_saves_answer_4xx_naming_the_file() {
    let server = Server::start(|dir| {
        let locked = dir.join("locked.toml");
        std::fs::write(&locked, "# locked\n").unwrap();
        let mut p = std::fs::metadata(&locked).unwrap().permissions();
        p.set_readonly(true);
        std::fs::set_permissions(&locked, p).unwrap();
        let shelf = dir.join("shelf");
        std::fs::create_dir(&shelf).unwrap();
        let mut p = std::fs::metadata(&shelf).unwrap().permissions();
        p.set_readonly(true);
        std::fs::set_permissions(&shelf, p).unwrap();
    });
    let root = server.dir.path().canonicalize().unwrap();
    let long = format!("{}.toml", "n".repeat(300));
    for (name, status) in [
        ("locked.toml", 403),
        ("shelf/new.toml", 403),
        (long.as_str(), 400),
    ] {
        let body = format!(r#"{{"path":"{name}"}}"#);
        let answer = server
            .request("POST", "/api/save", body.as_bytes())
            .unwrap_or_else(|| panic!("no answer to saving {name}"));
        let (got, message) = status_and_error(&answer);
        assert_eq!(got, status, "{answer}");
        assert!(
            message.starts_with(&format!("'{}", &name[..name.len().min(20)])),
            "{message}"
        );
        assert!(!message.contains(&*root.to_string_lossy()), "{message}");
        assert!(
            !message.contains("--force") && !message.contains('\n'),
            "{message}"
        );
        assert!(message.chars().count() < 200, "{message}");
    }
    assert_eq!(
        std::fs::read_to_string(server.dir.path().join("locked.toml")).unwrap(),
        "# locked\n"
    );
    let shelf = server.dir.path().join("shelf");
    assert_eq!(std::fs::read_dir(&shelf).unwrap().count(), 0);
    // A good save still works.
    let answer = server
        .request("POST", "/api/save", br#"{"path":"ok.toml"}"#)
        .unwrap();
    assert!(answer.starts_with("HTTP/1.1 200"), "{answer}");
}

/// A request the server answers without needing its body (`POST /api/new` with one) gets its
/// answer, not a reset; every error status, a wrong method's 405 too, carries a JSON message.
#[cfg(unix)]
#[test]
fn bodies_are_read_before_answers_and_every_error_has_a_message() {
    let server = Server::start(|_| {});
    let body = vec![b' '; 200 * 1024];
    for _ in 0..5 {
        let answer = server
            .request("POST", "/api/new", &body)
            .expect("the connection was reset before the answer");
        assert!(answer.starts_with("HTTP/1.1 200"), "{}", &answer[..40]);
    }
    let answer = server.request("GET", "/api/new", b"").unwrap();
    let (status, message) = status_and_error(&answer);
    assert_eq!(status, 405);
    assert!(message.contains("GET is not allowed"), "{message}");
    let answer = server
        .request("POST", "/api/edit", &vec![b'x'; 300 * 1024])
        .unwrap();
    let (status, message) = status_and_error(&answer);
    assert_eq!(status, 413);
    assert!(message.contains("KiB"), "{message}");
}

/// A connection that sends part of its headers, or part of its body, is closed after the
/// server's read timeouts (5 s); at most 64 connections are open at once, so a request made
/// while 64 idle ones are open is answered only once they are closed.
#[cfg(unix)]
#[test]
fn slow_connections_are_closed_and_connections_are_bounded() {
    use std::time::{Duration, Instant};
    let server = Server::start(|_| {});
    let start = Instant::now();
    let mut partial = std::net::TcpStream::connect(&server.host).unwrap();
    partial
        .write_all(b"GET /api/files HTTP/1.1\r\nHost: ")
        .unwrap();
    let mut slow_body = std::net::TcpStream::connect(&server.host).unwrap();
    write!(
        slow_body,
        "POST /api/new HTTP/1.1\r\nHost: {}\r\nx-pdeshape-token: {}\r\nContent-Length: 100\r\n\r\nabc",
        server.host, server.token
    )
    .unwrap();
    for s in [&partial, &slow_body] {
        s.set_read_timeout(Some(Duration::from_secs(15))).unwrap();
    }
    // The partial headers: closed without an answer (or with one), never held open.
    let mut got = Vec::new();
    let closed = (&partial).read_to_end(&mut got);
    assert!(
        !matches!(&closed, Err(e) if matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut)),
        "the connection was not closed: {closed:?}"
    );
    let mut answer = Vec::new();
    let _ = (&slow_body).read_to_end(&mut answer);
    let answer = String::from_utf8_lossy(&answer).into_owned();
    assert!(answer.starts_with("HTTP/1.1 408"), "{answer}");
    let waited = start.elapsed();
    assert!(
        waited >= Duration::from_secs(4) && waited < Duration::from_secs(12),
        "{waited:?}"
    );
    // 64 idle connections hold every place; the next request waits for the timeout to free one.
    let idle: Vec<_> = (0..64)
        .map(|_| std::net::TcpStream::connect(&server.host).unwrap())
        .collect();
    std::thread::sleep(Duration::from_millis(300));
    let start = Instant::now();
    let answer = server.request("GET", "/api/files", b"").unwrap();
    assert!(answer.starts_with("HTTP/1.1 200"), "{answer}");
    let waited = start.elapsed();
    assert!(
        waited >= Duration::from_secs(3) && waited < Duration::from_secs(12),
        "answered after {waited:?} with 64 connections open"
    );
    drop(idle);
}

/// A design given by an absolute path outside the current directory is served from its own
/// folder; with `--root`, from the root (the design named relative to it); a design outside
/// `--root` is refused with one line.
#[cfg(unix)]
#[test]
fn absolute_design_paths_and_root() {
    let elsewhere = tempfile::tempdir().unwrap();
    let sub = elsewhere.path().join("sub");
    std::fs::create_dir(&sub).unwrap();
    let cup = sub.join("cup.toml");
    std::fs::copy(pdeshape_testkit::example_path("cup.toml"), &cup).unwrap();
    let files = |server: &Server| {
        let answer = server.request("GET", "/api/files", b"").unwrap();
        assert!(answer.starts_with("HTTP/1.1 200"), "{answer}");
        let body = answer.split_once("\r\n\r\n").map_or("", |(_, b)| b);
        serde_json::from_str::<serde_json::Value>(body).unwrap()
    };
    let shown = |v: &serde_json::Value| v.to_string();
    let server = Server::start_with(&[cup.to_str().unwrap()], |_| {});
    let listed = files(&server);
    assert!(shown(&listed).contains("\"cup.toml\""), "{listed}");
    assert!(!shown(&listed).contains("sub/"), "{listed}");
    drop(server);
    let root = elsewhere.path().to_str().unwrap().to_string();
    let server = Server::start_with(&["--root", &root, cup.to_str().unwrap()], |_| {});
    let listed = files(&server);
    assert!(shown(&listed).contains("sub/cup.toml"), "{listed}");
    drop(server);
    let other = tempfile::tempdir().unwrap();
    let out = pdeshape()
        .args([
            "serve",
            "--port",
            "0",
            "--root",
            other.path().to_str().unwrap(),
        ])
        .arg(&cup)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("lies outside --root"), "{err}");
}
