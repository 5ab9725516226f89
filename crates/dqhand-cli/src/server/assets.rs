//! The built page's files, and nothing else: a request path is resolved inside the asset
//! directory or refused.

use std::net::TcpStream;
use std::path::{Component, Path, PathBuf};

use super::request::{respond, Request};

/// Largest file served (the page's bundles are a few hundred KiB).
const MAX_FILE_BYTES: u64 = 64 * 1024 * 1024;

/// Serves a GET or HEAD for a file of `root`.
pub fn serve(stream: &TcpStream, request: &Request, root: &Path) -> std::io::Result<()> {
    let head_only = request.method == "HEAD";
    if request.method != "GET" && !head_only {
        return respond(stream, 405, "text/plain", b"only GET and HEAD\n", false);
    }
    let Some(file) = resolve(root, &request.path) else {
        return respond(stream, 404, "text/plain", b"not found\n", head_only);
    };
    match std::fs::read(&file) {
        Ok(body) => respond(stream, 200, content_type(&file), &body, head_only),
        Err(_) => respond(stream, 404, "text/plain", b"not found\n", head_only),
    }
}

/// The file a URL path names inside `root` (canonical), or `None` if it names anything else:
/// no `..`, no absolute or drive prefixes, no backslashes, no symbolic link leading out.
pub fn resolve(root: &Path, url_path: &str) -> Option<PathBuf> {
    let relative = url_path.strip_prefix('/')?;
    let relative = if relative.is_empty() || relative.ends_with('/') { format!("{relative}index.html") } else { relative.into() };
    if relative.contains(['\\', '\0']) {
        return None;
    }
    let relative = Path::new(&relative);
    if !relative.components().all(|c| matches!(c, Component::Normal(_))) {
        return None;
    }
    let file = root.join(relative).canonicalize().ok()?;
    let meta = file.metadata().ok()?;
    (file.starts_with(root) && meta.is_file() && meta.len() <= MAX_FILE_BYTES).then_some(file)
}

fn content_type(file: &Path) -> &'static str {
    match file.extension().and_then(|e| e.to_str()).unwrap_or("") {
        "html" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "json" | "map" => "application/json",
        "png" => "image/png",
        "svg" => "image/svg+xml",
        "ico" => "image/x-icon",
        "glb" => "model/gltf-binary",
        "wasm" => "application/wasm",
        "txt" => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

#[cfg(test)]
mod tests {
    use super::resolve;

    #[test]
    fn only_files_inside_the_root() {
        let dir = std::env::temp_dir().join(format!("dqhand-assets-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("assets")).unwrap();
        std::fs::write(dir.join("index.html"), "<html>").unwrap();
        std::fs::write(dir.join("assets/app.js"), "").unwrap();
        let root = dir.canonicalize().unwrap();
        assert_eq!(resolve(&root, "/"), Some(root.join("index.html")));
        assert_eq!(resolve(&root, "/assets/app.js"), Some(root.join("assets/app.js")));
        for bad in ["/../Cargo.toml", "/assets/../../x", "//etc/passwd", "/assets\\..\\index.html", "/assets", "/missing.js", "relative", "/./index.html"] {
            assert_eq!(resolve(&root, bad), None, "{bad}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
