//! `pdeshape serve [DESIGN]`: the browser designer. A local web server (axum on tokio) serves an
//! embedded page (plain ES modules, WebGL2) that shows the design's surfaces (trimmed ones with
//! their holes), curves, derivative vectors and spines, the `(u, v)` plane of a patch with its
//! trim and attachment curves, and a timeline for time-dependent designs; it sends edits (drags
//! of control points, spine handles, trim curves and attachments, local edits, transforms, `a`,
//! order, modes, design parameters, curves and patches) as the library's edit values; the
//! compiled design re-solves what changed and the meshes come back in a binary frame.

mod assets;
mod error;
mod files;
mod gestures;
mod http;
mod library;
mod scene;
mod session;
mod socket;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_ops;
#[cfg(test)]
mod tests_socket;
mod timeline;
mod trimmed;
mod uv;

use crate::common::{self, CliError};
use std::net::{IpAddr, SocketAddr};
use std::sync::Arc;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file to start from (any path); without it, a small starting design. Files
    /// are listed, loaded and saved inside the start directory: `--root`, else the current
    /// directory when the design lies inside it, else the design's own directory.
    pub design: Option<String>,
    /// The start directory (default: the current directory, or the design's own directory
    /// when the design lies outside the current one).
    #[arg(long, value_name = "DIR")]
    pub root: Option<std::path::PathBuf>,
    /// Port to listen on (0: any free port).
    #[arg(long, default_value_t = 8737)]
    pub port: u16,
    /// Address to listen on. Anything but loopback lets other machines reach the designer
    /// (they still need the token).
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// Open the page in the default browser.
    #[arg(long)]
    pub open: bool,
}

/// A line on stderr; a closed stderr is ignored (the server goes on).
fn note(text: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{text}");
}

/// A fresh random token (128 bits from the operating system's generator, hex).
fn new_token() -> String {
    use rand::RngCore;
    let mut bytes = [0u8; 16];
    rand::rngs::OsRng.fill_bytes(&mut bytes);
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Connections open at once: more wait in the listening socket's backlog until one closes.
const MAX_CONNECTIONS: usize = 64;
/// A request's headers must arrive within this time (also the wait for the next request on a
/// kept-alive connection); its body within [`http::BODY_TIMEOUT`]. Slower connections are
/// closed.
const HEADER_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);

/// Serves `router` on `listener` until Ctrl-C: at most [`MAX_CONNECTIONS`] connections at once,
/// each closed when its headers take longer than [`HEADER_TIMEOUT`].
async fn serve_bounded(listener: tokio::net::TcpListener, router: axum::Router) {
    let open = Arc::new(tokio::sync::Semaphore::new(MAX_CONNECTIONS));
    let stop = tokio::signal::ctrl_c();
    tokio::pin!(stop);
    loop {
        let permit = tokio::select! {
            p = open.clone().acquire_owned() => match p {
                Ok(p) => p,
                Err(_) => break,
            },
            _ = &mut stop => break,
        };
        let stream = tokio::select! {
            a = listener.accept() => match a {
                Ok((stream, _)) => stream,
                // Out of descriptors and the like: wait a moment, go on serving.
                Err(_) => {
                    tokio::time::sleep(std::time::Duration::from_millis(50)).await;
                    continue;
                }
            },
            _ = &mut stop => break,
        };
        // Frames go out as soon as they are written (no Nagle delay on the last segment).
        let _ = stream.set_nodelay(true);
        let service = hyper_util::service::TowerToHyperService::new(router.clone());
        tokio::spawn(async move {
            let _permit = permit;
            let _ = hyper::server::conn::http1::Builder::new()
                .timer(hyper_util::rt::TokioTimer::new())
                .header_read_timeout(HEADER_TIMEOUT)
                .serve_connection(hyper_util::rt::TokioIo::new(stream), service)
                .with_upgrades()
                .await;
        });
    }
    note("stopping");
}

/// The start directory and the design inside it: `--root` (the design must lie inside it), else
/// the current directory when the design lies inside it, else the design's own directory. A
/// design that cannot be resolved (missing) is left to the session to word its error.
fn start_dir(args: &Args) -> Result<(std::path::PathBuf, Option<String>), CliError> {
    let cwd = std::env::current_dir()
        .map_err(|e| CliError::input(format!("cannot read the current directory: {e}")))?;
    let root = match &args.root {
        Some(r) => {
            let c = cwd.join(r).canonicalize().map_err(|e| {
                CliError::input(format!("--root {}: {}", r.display(), common::io_words(&e)))
            })?;
            if !c.is_dir() {
                return Err(CliError::input(format!(
                    "--root {}: not a directory",
                    r.display()
                )));
            }
            Some(c)
        }
        None => None,
    };
    let Some(design) = &args.design else {
        return Ok((root.unwrap_or(cwd), None));
    };
    let Ok(full) = cwd.join(design).canonicalize() else {
        return Ok((root.unwrap_or(cwd), Some(design.clone())));
    };
    let rel_to = |dir: &std::path::Path| {
        full.strip_prefix(dir)
            .ok()
            .and_then(|r| r.to_str())
            .map(str::to_string)
    };
    if let Some(root) = root {
        return match rel_to(&root) {
            Some(rel) => Ok((root, Some(rel))),
            None => Err(CliError::input(format!(
                "{design}: lies outside --root {}",
                root.display()
            ))),
        };
    }
    if let Some(rel) = cwd.canonicalize().ok().and_then(|c| rel_to(&c)) {
        return Ok((cwd, Some(rel)));
    }
    match (full.parent(), full.file_name().and_then(|n| n.to_str())) {
        (Some(dir), Some(name)) => Ok((dir.to_path_buf(), Some(name.to_string()))),
        _ => Ok((cwd, Some(design.clone()))),
    }
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let (root, design) = start_dir(args)?;
    let session = session::Session::open(root, design.as_deref()).map_err(|e| {
        let place = if e.place.is_empty() || e.message.contains(&e.place) {
            String::new()
        } else {
            format!("{}: ", e.place)
        };
        CliError::input(format!("{place}{}", e.message))
    })?;
    let (ip, host_name): (IpAddr, Option<String>) = match args.host.parse::<IpAddr>() {
        Ok(ip) => (ip, None),
        Err(_) if args.host.eq_ignore_ascii_case("localhost") => {
            (IpAddr::from([127, 0, 0, 1]), None)
        }
        Err(_) => {
            return Err(CliError::input(format!(
                "--host: expected an IP address such as 127.0.0.1 or ::1 (got '{}')",
                args.host
            )))
        }
    };
    if !ip.is_loopback() {
        note(&format!(
            "warning: listening on {ip}, not on loopback: other machines can reach the designer \
             (every request still needs the token in the printed URL)"
        ));
    }
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| CliError::input(format!("cannot start the server: {e}")))?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(SocketAddr::new(ip, args.port))
            .await
            .map_err(|e| {
                CliError::input(format!("--port {}: cannot listen on {ip}: {e}", args.port))
            })?;
        let port = listener
            .local_addr()
            .map_err(|e| CliError::input(format!("cannot read the listening address: {e}")))?
            .port();
        let token = new_token();
        let shown = if ip.is_unspecified() || ip.is_loopback() {
            if ip.is_ipv6() {
                "[::1]".to_string()
            } else {
                "127.0.0.1".to_string()
            }
        } else if ip.is_ipv6() {
            format!("[{ip}]")
        } else {
            ip.to_string()
        };
        let url = format!("http://{shown}:{port}/?token={token}");
        let state = http::AppState {
            session: Arc::new(tokio::sync::Mutex::new(session)),
            token: token.into(),
            port,
            host_name,
        };
        // A closed stdout (`pdeshape serve | head -1`) must not stop the server.
        crate::common::print_stdout(&format!("pdeshape designer: {url}\n(Ctrl-C stops it)\n"));
        if args.open {
            if let Err(e) = std::process::Command::new("xdg-open").arg(&url).spawn() {
                note(&format!(
                    "warning: --open: cannot start a browser ({e}); open the URL above"
                ));
            }
        }
        serve_bounded(listener, http::router(state)).await;
        Ok::<(), CliError>(())
    })?;
    // Blocking work still queued is not waited for beyond a moment.
    runtime.shutdown_timeout(std::time::Duration::from_secs(2));
    Ok(())
}
