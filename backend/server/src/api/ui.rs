//! The commissioning UI: the files `npm run build` writes to `frontend/dist`, served at `/`.
//!
//! Everything that is not an API route falls through to here: a file of the UI directory, or
//! `index.html` for any other path without a file extension (the single-page app routes it).
//! Vite names its bundles by content hash under `assets/`, so those are cached for a year; the
//! rest (index.html above all) is revalidated on every load. Paths under `/api` never reach
//! the UI: they are the API's problem+json 404.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use axum::body::Body;
use axum::extract::{Request, State};
use axum::http::{HeaderValue, Method, StatusCode, header};
use axum::response::{Html, IntoResponse, Response};
use tower::ServiceExt;
use tower_http::services::{ServeDir, ServeFile};

use crate::app::AppState;

/// How to build the UI (shown on `/` while it is missing, and logged).
pub const BUILD_COMMAND: &str = "npm --prefix frontend ci && npm --prefix frontend run build";

/// The UI directory: `--ui-dir` if given; else `frontend/dist` in the current directory; else
/// the one in the workspace this binary was built from; else `frontend/dist` (missing).
pub fn resolve_dir(arg: Option<&Path>) -> PathBuf {
    if let Some(p) = arg {
        return p.to_path_buf();
    }
    let local = PathBuf::from("frontend/dist");
    if is_built(&local) {
        return local;
    }
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../frontend/dist");
    if is_built(&workspace) {
        return workspace.canonicalize().unwrap_or(workspace);
    }
    local
}

pub fn is_built(dir: &Path) -> bool {
    dir.join("index.html").is_file()
}

/// The last path segment has an extension: a file was asked for, not a page.
fn looks_like_file(path: &str) -> bool {
    path.rsplit('/').next().is_some_and(|s| s.contains('.'))
}

/// The fallback of the router: the UI's files, `index.html` for the app's routes.
pub async fn serve(State(s): State<Arc<AppState>>, req: Request) -> Response {
    let path = req.uri().path().to_string();
    if path == "/api" || path.starts_with("/api/") {
        return super::not_found(req.uri().clone()).await;
    }
    if req.method() != Method::GET && req.method() != Method::HEAD {
        return super::not_found(req.uri().clone()).await;
    }
    let dir = &s.info.ui_dir;
    if !is_built(dir) {
        if looks_like_file(&path) && path != "/index.html" {
            return super::not_found(req.uri().clone()).await;
        }
        return not_built(dir);
    }
    let (parts, body) = req.into_parts();
    let again = Request::from_parts(parts.clone(), Body::empty());
    let req = Request::from_parts(parts, body);
    let mut resp = match ServeDir::new(dir).oneshot(req).await {
        Ok(r) => r.map(Body::new),
        Err(e) => match e {},
    };
    if resp.status() == StatusCode::NOT_FOUND {
        if looks_like_file(&path) {
            return super::not_found(again.uri().clone()).await;
        }
        resp = match ServeFile::new(dir.join("index.html")).oneshot(again).await {
            Ok(r) => r.map(Body::new),
            Err(e) => match e {},
        };
    }
    let cache = if path.starts_with("/assets/") && resp.status().is_success() {
        "public, max-age=31536000, immutable"
    } else {
        "no-cache"
    };
    resp.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static(cache));
    resp
}

fn not_built(dir: &Path) -> Response {
    let page = format!(
        concat!(
            "<!doctype html><meta charset=utf-8><title>motiond</title>",
            "<h1>motiond</h1><p>The commissioning UI is not built: there is no <code>index.html</code> in ",
            "<code>{dir}</code>. Build it in the source tree with</p><pre>{build}</pre>",
            "<p>(it needs Node.js and npm: <code>apt-get install nodejs npm</code>) or start motiond with ",
            "<code>./scripts/run.sh</code>, which does that for you; <code>--ui-dir</code> points motiond at ",
            "another directory.</p><p>The API works without it: <a href=/docs>Swagger UI</a>, ",
            "<a href=/openapi.json>openapi.json</a>, <a href=/api/v1/axes>/api/v1/axes</a>, ",
            "<a href=/api/v1/system>/api/v1/system</a>, <a href=/metrics>/metrics</a>.</p>"
        ),
        dir = html_escape(&dir.display().to_string()),
        build = html_escape(BUILD_COMMAND),
    );
    let mut r = Html(page).into_response();
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    r
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
