//! `serve`: the built web site (`src/web/build.sh` writes it to `site` in
//! cargo's target folder) over HTTP on 127.0.0.1 only, for a browser on
//! this machine: GET and HEAD of the files under the site folder, nothing
//! else.

use crate::ServeArgs;
use anyhow::{Context, Result, bail};
use std::fs::File;
use std::io::{ErrorKind, Write};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tiny_http::{Header, Method, Request, Response, Server, StatusCode};

/// Threads answering requests, so that a browser's parallel fetches (six
/// at a time per host) are not served one after the other.
const WORKERS: usize = 8;

/// Where `src/web/build.sh` puts the site by default: `site` in cargo's
/// target folder, `$CARGO_TARGET_DIR` where set (relative to the current
/// folder, as for cargo), else `target`.
fn default_site() -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .filter(|d| !d.is_empty())
        .map_or_else(|| PathBuf::from("target"), PathBuf::from)
        .join("site")
}

/// Serves `args.site` (or [`default_site`]) until the process is killed.
pub fn serve(args: &ServeArgs) -> Result<()> {
    let site = args.site.clone().unwrap_or_else(default_site);
    let root = site_root(&site)?;
    let listener = TcpListener::bind(("127.0.0.1", args.port)).map_err(|e| {
        if e.kind() == ErrorKind::AddrInUse {
            anyhow::anyhow!(
                "port {} is in use (pick another with --port P, or --port 0 for a free one)",
                args.port
            )
        } else {
            anyhow::Error::new(e).context(format!("cannot listen on 127.0.0.1:{}", args.port))
        }
    })?;
    let port = listener.local_addr()?.port();
    let server = Server::from_listener(listener, None)
        .map_err(|e| anyhow::anyhow!("cannot start the server on port {port}: {e}"))?;
    let server = Arc::new(server);

    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "serving {} at http://127.0.0.1:{port}/",
        site.display()
    )?;
    out.flush()?;
    drop(out);

    let workers: Vec<_> = (1..WORKERS)
        .map(|i| {
            let server = Arc::clone(&server);
            let root = root.clone();
            std::thread::Builder::new()
                .name(format!("serve-{i}"))
                .spawn(move || answer_all(&server, &root))
                .context("cannot start a server thread")
        })
        .collect::<Result<_>>()?;
    let result = answer_all(&server, &root);
    for w in workers {
        let _ = w.join();
    }
    result
}

/// The site folder, canonical, after checking that it holds `index.html`.
fn site_root(site: &Path) -> Result<PathBuf> {
    let build = "build it with src/web/build.sh";
    if !site.is_dir() {
        bail!("no site folder {}: {build}", site.display());
    }
    if !site.join("index.html").is_file() {
        bail!("{} holds no index.html: {build}", site.display());
    }
    site.canonicalize()
        .with_context(|| format!("cannot resolve {}", site.display()))
}

/// Answers requests until the server stops.
fn answer_all(server: &Server, root: &Path) -> Result<()> {
    loop {
        let request = server.recv().context("the server stopped")?;
        let url = request.url().to_owned();
        if let Err(e) = answer(request, root) {
            eprintln!("error: {url}: {e}");
        }
    }
}

/// Answers one request.
fn answer(request: Request, root: &Path) -> std::io::Result<()> {
    if !matches!(request.method(), Method::Get | Method::Head) {
        let allow = header("Allow", "GET, HEAD");
        return request.respond(status(405).with_header(allow));
    }
    match lookup(root, request.url()) {
        Found::File(path) => {
            // The site's build keeps gzipped copies of its largest files
            // (the wasm and its glue): sent as they are where the browser
            // takes gzip.
            let gzip = accepts_gzip(&request)
                .then(|| gzipped(root, &path))
                .flatten()
                .and_then(|gz| File::open(gz).ok());
            let encoded = gzip.is_some();
            match gzip.map(Ok).unwrap_or_else(|| File::open(&path)) {
                Ok(file) => {
                    let mut response = Response::from_file(file)
                        // Content-Length rather than chunks, whatever the size.
                        .with_chunked_threshold(usize::MAX)
                        .with_header(header("Content-Type", content_type(&path)))
                        .with_header(header("Cache-Control", "no-cache"))
                        .with_header(header("Vary", "Accept-Encoding"));
                    if encoded {
                        response.add_header(header("Content-Encoding", "gzip"));
                    }
                    request.respond(response)
                }
                Err(_) => request.respond(status(404)),
            }
        }
        Found::Folder(location) => match Header::from_bytes("Location", location.as_bytes()) {
            Ok(h) => request.respond(status(302).with_header(h)),
            Err(()) => request.respond(status(400)),
        },
        Found::BadRequest => request.respond(status(400)),
        Found::Nothing => request.respond(status(404)),
    }
}

/// Whether the request's Accept-Encoding takes gzip.
fn accepts_gzip(request: &Request) -> bool {
    request.headers().iter().any(|h| {
        h.field.equiv("Accept-Encoding")
            && h.value.as_str().split(',').any(|e| {
                let mut parts = e.split(';');
                let name = parts.next().unwrap_or("").trim();
                // `q=0` (or 0.0, 0.000) refuses it.
                let refused = parts.any(|p| {
                    p.trim()
                        .strip_prefix("q=")
                        .and_then(|q| q.trim().parse::<f64>().ok())
                        .is_some_and(|q| q == 0.0)
                });
                name.eq_ignore_ascii_case("gzip") && !refused
            })
    })
}

/// The gzipped copy of `path` beside it, if it lies in `root` and is not
/// older than the file (a file rebuilt by hand is sent as it is).
fn gzipped(root: &Path, path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?.to_string_lossy();
    let gz = inside(root, &path.with_file_name(format!("{name}.gz")))?;
    let modified = |p: &Path| p.metadata().and_then(|m| m.modified()).ok();
    (gz.is_file() && modified(&gz)? >= modified(path)?).then_some(gz)
}

/// What a request's path names.
#[derive(Debug, PartialEq)]
enum Found {
    /// A file under the site folder (canonical path).
    File(PathBuf),
    /// A folder asked for without its closing `/`: where to send the
    /// browser, so that the page's relative links resolve inside it.
    Folder(String),
    /// A malformed path (bad percent escape, not UTF-8).
    BadRequest,
    /// Nothing there, or outside the site folder.
    Nothing,
}

/// Resolves the request target `url` under the canonical `root`: the query
/// and fragment are dropped, the path percent-decoded, `..` refused, a
/// folder gives its `index.html`, and whatever resolves (through symbolic
/// links) outside `root` is nothing.
fn lookup(root: &Path, url: &str) -> Found {
    let (raw, rest) = url.split_at(url.find(['?', '#']).unwrap_or(url.len()));
    let query = match rest.find('#') {
        _ if !rest.starts_with('?') => "",
        Some(hash) => &rest[..hash],
        None => rest,
    };
    if !raw.starts_with('/') {
        return Found::Nothing;
    }
    let Some(path) = percent_decode(raw) else {
        return Found::BadRequest;
    };
    let mut full = root.to_path_buf();
    for part in path.split('/') {
        match part {
            "" | "." => {}
            ".." => return Found::Nothing,
            p if p.contains('\0') || p.contains('\\') => return Found::Nothing,
            p => full.push(p),
        }
    }
    let Some(found) = inside(root, &full) else {
        return Found::Nothing;
    };
    if found.is_dir() {
        if !path.ends_with('/') {
            // One leading `/`: `//host/` would send the browser elsewhere.
            let raw = raw.trim_start_matches('/');
            return Found::Folder(format!("/{raw}/{query}"));
        }
        return match inside(root, &found.join("index.html")) {
            Some(index) if index.is_file() => Found::File(index),
            _ => Found::Nothing,
        };
    }
    if found.is_file() {
        Found::File(found)
    } else {
        Found::Nothing
    }
}

/// `path` resolved through its symbolic links, if it exists and lies in
/// `root`.
fn inside(root: &Path, path: &Path) -> Option<PathBuf> {
    let real = path.canonicalize().ok()?;
    real.starts_with(root).then_some(real)
}

/// `%XX` escapes decoded (`+` stays `+`: it is a space only in queries);
/// `None` for a bad escape or a result that is not UTF-8.
fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The Content-Type for a file, by its extension.
fn content_type(path: &Path) -> &'static str {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "html" | "htm" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "wasm" => "application/wasm",
        "css" => "text/css; charset=utf-8",
        "json" | "map" => "application/json",
        "toml" | "txt" | "md" | "wgsl" => "text/plain; charset=utf-8",
        "csv" => "text/csv; charset=utf-8",
        "obj" => "model/obj",
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "gif" => "image/gif",
        "svg" => "image/svg+xml",
        "ico" => "image/x-icon",
        "webp" => "image/webp",
        "mp4" => "video/mp4",
        _ => "application/octet-stream",
    }
}

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("ASCII header")
}

/// An empty response with `code`, not cached either.
fn status(code: u16) -> Response<std::io::Empty> {
    Response::empty(StatusCode(code)).with_header(header("Cache-Control", "no-cache"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_escapes_decode_and_bad_ones_are_refused() {
        assert_eq!(percent_decode("/a%20b%2Ec").as_deref(), Some("/a b.c"));
        assert_eq!(percent_decode("/a+b").as_deref(), Some("/a+b"));
        assert_eq!(percent_decode("/a%2"), None);
        assert_eq!(percent_decode("/a%zz"), None);
        assert_eq!(percent_decode("/%ff"), None);
    }

    #[test]
    fn paths_resolve_inside_the_site_only() {
        let dir = tempfile::tempdir().unwrap();
        let site = dir.path().join("site");
        std::fs::create_dir_all(site.join("sub")).unwrap();
        std::fs::write(site.join("index.html"), "i").unwrap();
        std::fs::write(site.join("sub/x.toml"), "x").unwrap();
        std::fs::write(dir.path().join("secret"), "s").unwrap();
        std::os::unix::fs::symlink(dir.path().join("secret"), site.join("out")).unwrap();
        let root = site.canonicalize().unwrap();
        let file = |p: &str| Found::File(root.join(p));
        assert_eq!(lookup(&root, "/"), file("index.html"));
        assert_eq!(lookup(&root, "/?v=2"), file("index.html"));
        assert_eq!(lookup(&root, "/sub/x.toml?x#y"), file("sub/x.toml"));
        assert_eq!(lookup(&root, "/sub/./x%2Etoml"), file("sub/x.toml"));
        assert_eq!(lookup(&root, "/sub?a=1"), Found::Folder("/sub/?a=1".into()));
        assert_eq!(lookup(&root, "//sub#a"), Found::Folder("/sub/".into()));
        assert_eq!(lookup(&root, "/sub/"), Found::Nothing);
        for bad in [
            "/../secret",
            "/%2e%2e/secret",
            "/sub/%2E%2E/%2e%2e/secret",
            "/out",
            "//etc/passwd",
            "/missing",
            "secret",
            "/a%00b",
        ] {
            assert_eq!(lookup(&root, bad), Found::Nothing, "{bad}");
        }
        assert_eq!(lookup(&root, "/%zz"), Found::BadRequest);
    }

    #[test]
    fn content_types_by_extension() {
        let t = |p: &str| content_type(Path::new(p));
        assert_eq!(t("a.wasm"), "application/wasm");
        assert_eq!(t("a.JS"), "text/javascript; charset=utf-8");
        assert_eq!(t("c/x.toml"), "text/plain; charset=utf-8");
        assert_eq!(t("s.exr"), "application/octet-stream");
        assert_eq!(t("noext"), "application/octet-stream");
    }
}
