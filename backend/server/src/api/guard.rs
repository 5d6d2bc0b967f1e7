//! What a request goes through before a handler, so that a web page in the engineer's browser
//! cannot act on motiond for another site (docs/security.md):
//!
//! 1. [`check_host`], every request (a layer around the whole router): a request line of at
//!    most [`MAX_URI`] bytes (else 414 `uri_too_long`) and headers of at most [`MAX_HEADERS`]
//!    bytes (else 431 `request_headers_too_large`) — beyond 64 KiB, or 100 headers, hyper
//!    itself answers 414 / 431 without a body —; `Host` names this server — a loopback name or
//!    address, or a `--public-name` — else 421 `misdirected_request` (DNS rebinding: a foreign
//!    name that resolves to 127.0.0.1).
//! 2. [`check_request`], every request to `/api/v1/…` (a layer of that router, so before its
//!    routing): a state-changing one (any method but GET, HEAD, OPTIONS, TRACE) or a websocket
//!    upgrade must not come from another origin — `Origin`, when sent, this server's own or one
//!    given with `--allow-origin`; `Sec-Fetch-Site`, when sent, `same-origin` or `none` unless
//!    the origin is allowed — else 403 `cross_origin_forbidden`. A state-changing one must then
//!    declare `Content-Type: application/json` (with or without a body), else 415
//!    `unsupported_media_type`: a browser sends that type across origins only after a CORS
//!    preflight, which motiond never grants.
//! 3. Routing: an unknown path is a 404, a method the route does not take a 405.
//! 4. The body ([`super::JsonBody`]): at most 2 MiB (413), JSON (400), an object (422).

use std::net::{Ipv4Addr, Ipv6Addr};
use std::sync::Arc;

use axum::extract::{Request, State};
use axum::http::{HeaderMap, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use crate::error::AppError;

/// The names motiond serves besides loopback ones, and the foreign origins it trusts.
#[derive(Clone, Debug, Default)]
pub struct Guard {
    /// `--public-name`: host names (lower case, IPv6 in brackets), any port.
    pub public_names: Vec<String>,
    /// `--allow-origin`: origins as browsers send them (`scheme://host[:port]`, lower case,
    /// no default port).
    pub allowed_origins: Vec<String>,
}

impl Guard {
    /// Whether `host` (as [`split_authority`] gives it) is a name this server answers to.
    fn serves(&self, host: &str) -> bool {
        is_loopback(host) || self.public_names.iter().any(|n| n == host)
    }

    /// Why the request is for a host this server does not serve, if it is.
    fn misdirected(&self, req: &Request) -> Option<String> {
        let mut hosts = req.headers().get_all(header::HOST).iter();
        let host = hosts.next();
        if hosts.next().is_some() {
            return Some("the request has several Host headers".into());
        }
        // An absolute-form target (`GET http://name/ …`) names a host too.
        let authority = req.uri().authority().map(|a| a.as_str().as_bytes());
        for name in host.map(|h| h.as_bytes()).into_iter().chain(authority) {
            let text = String::from_utf8_lossy(name);
            if !split_authority(&text).is_some_and(|(host, _)| self.serves(&host)) {
                return Some(not_served(&text));
            }
        }
        // No Host at all (HTTP/1.0): no browser sends such a request, so it is no rebinding.
        None
    }

    /// Why a state-changing request or a websocket upgrade counts as cross-origin, if it does.
    fn cross_origin(&self, headers: &HeaderMap) -> Option<String> {
        let mut origins = headers.get_all(header::ORIGIN).iter();
        let origin = origins.next();
        if origins.next().is_some() {
            return Some("the request has several Origin headers".into());
        }
        if let Some(origin) = origin {
            let text = String::from_utf8_lossy(origin.as_bytes());
            if normalize_origin(&text).is_some_and(|o| self.allowed_origins.contains(&o)) {
                return None;
            }
            let host = headers
                .get(header::HOST)
                .map(|h| String::from_utf8_lossy(h.as_bytes()).into_owned());
            if !host.as_deref().is_some_and(|h| same_origin(&text, h)) {
                return Some(foreign_origin(&text, host.as_deref()));
            }
        }
        for site in headers.get_all("sec-fetch-site") {
            let site = String::from_utf8_lossy(site.as_bytes());
            if site != "same-origin" && site != "none" {
                return Some(foreign_site(&site));
            }
        }
        None
    }
}

/// The longest URI (path and query) motiond reads: 8 KiB.
pub const MAX_URI: usize = 8 * 1024;
/// The most header bytes (names and values) motiond reads: 16 KiB.
pub const MAX_HEADERS: usize = 16 * 1024;

/// 414 / 431 for a request too large to be one of motiond's, then 421 for a request to a host
/// name this server does not serve (every request).
pub async fn check_host(State(g): State<Arc<Guard>>, req: Request, next: Next) -> Response {
    let uri = req.uri().path_and_query().map_or(0, |p| p.as_str().len());
    if uri > MAX_URI {
        return AppError::new(
            axum::http::StatusCode::URI_TOO_LONG,
            "uri_too_long",
            "URI too long",
            format!("the URI has {uri} bytes; at most {MAX_URI} are read"),
        )
        .into_response();
    }
    let headers: usize = req
        .headers()
        .iter()
        .map(|(n, v)| n.as_str().len() + v.len())
        .sum();
    if headers > MAX_HEADERS {
        return AppError::new(
            axum::http::StatusCode::REQUEST_HEADER_FIELDS_TOO_LARGE,
            "request_headers_too_large",
            "Request headers too large",
            format!("the headers have {headers} bytes; at most {MAX_HEADERS} are read"),
        )
        .into_response();
    }
    match g.misdirected(&req) {
        Some(detail) => AppError::misdirected(detail).into_response(),
        None => next.run(req).await,
    }
}

/// 403 for a state-changing request or a websocket upgrade from another origin, then 415 for a
/// state-changing request that is not declared JSON (a layer of the `/api/v1` router).
pub async fn check_request(State(g): State<Arc<Guard>>, req: Request, next: Next) -> Response {
    let changes = !req.method().is_safe();
    let upgrade = req.headers().contains_key(header::UPGRADE);
    if changes || upgrade {
        if let Some(detail) = g.cross_origin(req.headers()) {
            return AppError::cross_origin(detail).into_response();
        }
    }
    if changes {
        if let Err(detail) = json_content_type(req.headers()) {
            return AppError::unsupported_media_type(detail).into_response();
        }
    }
    next.run(req).await
}

/// `Content-Type: application/json`, parameters (`; charset=utf-8`) allowed.
fn json_content_type(headers: &HeaderMap) -> Result<(), String> {
    let mut types = headers.get_all(header::CONTENT_TYPE).iter();
    let detail = match (types.next(), types.next()) {
        (None, _) => "the request has no Content-Type".to_owned(),
        (Some(_), Some(_)) => "the request has several Content-Type headers".to_owned(),
        (Some(t), None) => {
            let text = String::from_utf8_lossy(t.as_bytes());
            let media = text.split(';').next().unwrap_or_default().trim();
            if media.eq_ignore_ascii_case("application/json") {
                return Ok(());
            }
            format!("Content-Type {text:?} is not application/json")
        }
    };
    Err(not_json(&detail))
}

// The details of the problems (also the OpenAPI document's examples).

pub(crate) fn not_served(host: &str) -> String {
    format!(
        "this server does not serve the host {host:?}: it answers to loopback names and \
         addresses (localhost, 127.0.0.1, [::1]) and to the names given with --public-name"
    )
}

pub(crate) fn foreign_origin(origin: &str, host: Option<&str>) -> String {
    format!(
        "a request from the web page at {origin:?} may not change anything here: Origin is \
         neither this server's own ({}) nor one allowed with --allow-origin",
        host.unwrap_or("no Host")
    )
}

pub(crate) fn foreign_site(site: &str) -> String {
    format!(
        "a request from another web page (Sec-Fetch-Site: {site}) may not change anything \
         here; only the server's own pages may (or an origin allowed with --allow-origin)"
    )
}

pub(crate) fn not_json(detail: &str) -> String {
    format!(
        "{detail}: every POST, PUT, PATCH and DELETE must be sent as Content-Type: \
         application/json, also without a body (curl: --json '{{…}}' or -H 'Content-Type: \
         application/json')"
    )
}

/// `host[:port]` (a Host header, an origin's authority) → the host in lower case (an IPv6
/// address in brackets) and the port, if given. `None` when it is not a valid host.
fn split_authority(s: &str) -> Option<(String, Option<u16>)> {
    let s = s.to_ascii_lowercase();
    let (host, port) = if s.starts_with('[') {
        s.split_at(s.find(']')? + 1)
    } else {
        s.split_at(s.find(':').unwrap_or(s.len()))
    };
    let port = match port {
        "" | ":" => None,
        p => {
            let digits = p.strip_prefix(':')?;
            if !digits.bytes().all(|b| b.is_ascii_digit()) {
                return None;
            }
            Some(digits.parse().ok()?)
        }
    };
    valid_host(host).then(|| (host.to_owned(), port))
}

/// A DNS name (labels of letters, digits, `-`, `_`), an IPv4 address or an IPv6 address in
/// brackets.
fn valid_host(h: &str) -> bool {
    if let Some(inner) = h.strip_prefix('[').and_then(|h| h.strip_suffix(']')) {
        return inner.parse::<Ipv6Addr>().is_ok();
    }
    !h.is_empty()
        && h.split('.').all(|label| {
            !label.is_empty()
                && label
                    .bytes()
                    .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_')
        })
}

/// `localhost`, `*.localhost` (RFC 6761: always loopback, never asked of DNS, so no one can
/// rebind them), 127.0.0.0/8 and `[::1]`.
fn is_loopback(host: &str) -> bool {
    host == "localhost"
        || host.ends_with(".localhost")
        || host.parse::<Ipv4Addr>().is_ok_and(|a| a.is_loopback())
        || host
            .strip_prefix('[')
            .and_then(|h| h.strip_suffix(']'))
            .and_then(|h| h.parse::<Ipv6Addr>().ok())
            .is_some_and(|a| a.is_loopback())
}

/// An origin (`http://host[:port]`, `https://…`) → (scheme, host, port or the scheme's default).
fn parse_origin(s: &str) -> Option<(&'static str, String, u16)> {
    let starts = |prefix: &str| {
        s.get(..prefix.len())
            .is_some_and(|p| p.eq_ignore_ascii_case(prefix))
    };
    let (scheme, default) = if starts("http://") {
        ("http", 80)
    } else if starts("https://") {
        ("https", 443)
    } else {
        return None;
    };
    let (host, port) = split_authority(&s[scheme.len() + 3..])?;
    Some((scheme, host, port.unwrap_or(default)))
}

/// An origin as a browser serialises it: lower case, without the scheme's default port.
fn normalize_origin(s: &str) -> Option<String> {
    let (scheme, host, port) = parse_origin(s)?;
    Some(match (scheme, port) {
        ("http", 80) | ("https", 443) => format!("{scheme}://{host}"),
        _ => format!("{scheme}://{host}:{port}"),
    })
}

/// Whether `origin` is the server the request was sent to: the same host and port as the
/// request's `Host` (a missing port is the origin scheme's default). The scheme is not compared:
/// one host and port is one listener, whether a proxy in front of it speaks TLS or not.
fn same_origin(origin: &str, host: &str) -> bool {
    let Some((scheme, o_host, o_port)) = parse_origin(origin) else {
        return false;
    };
    let default = if scheme == "http" { 80 } else { 443 };
    split_authority(host).is_some_and(|(h, p)| h == o_host && p.unwrap_or(default) == o_port)
}

/// `--public-name NAME`: a host name or address, without scheme or port.
pub fn parse_public_name(s: &str) -> Result<String, String> {
    let lower = s.to_ascii_lowercase();
    let name = match lower.parse::<Ipv6Addr>() {
        Ok(a) => format!("[{a}]"),
        Err(_) => lower,
    };
    if split_authority(&name).is_some_and(|(h, p)| h == name && p.is_none()) {
        Ok(name)
    } else {
        Err(format!(
            "{s:?} is not a host name or address (give the name alone, without scheme or port, \
             e.g. machine.example.com)"
        ))
    }
}

/// `--allow-origin ORIGIN`: `http[s]://host[:port]` (one trailing `/` tolerated).
pub fn parse_allow_origin(s: &str) -> Result<String, String> {
    normalize_origin(s.strip_suffix('/').unwrap_or(s)).ok_or_else(|| {
        format!(
            "{s:?} is not an origin: scheme://host[:port] with scheme http or https and nothing \
             after the port, e.g. http://localhost:5173 (null and * are never allowed)"
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use axum::http::HeaderValue;

    fn headers(pairs: &[(&'static str, &'static str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.append(*k, HeaderValue::from_static(v));
        }
        h
    }

    fn host_ok(g: &Guard, host: &'static str) -> bool {
        let req = Request::builder()
            .uri("/api/v1/axes")
            .header(header::HOST, host)
            .body(axum::body::Body::empty())
            .unwrap();
        g.misdirected(&req).is_none()
    }

    #[test]
    fn loopback_hosts_with_any_port_and_public_names_are_served() {
        let g = Guard {
            public_names: vec!["machine.example".into(), "[fd00::1]".into()],
            ..Guard::default()
        };
        for ok in [
            "127.0.0.1:8080",
            "127.0.0.1",
            "127.0.0.2:1",
            "127.255.255.254:65535",
            "localhost:5173",
            "LOCALHOST",
            "ui.localhost:80",
            "[::1]:8080",
            "[0:0:0:0:0:0:0:1]",
            "machine.example:443",
            "Machine.Example",
            "[fd00::1]:8080",
        ] {
            assert!(host_ok(&g, ok), "{ok} refused");
        }
        for refused in [
            "attacker.example",
            "attacker.example:8080",
            "128.0.0.1:8080",
            "0.0.0.0:8080",
            "10.0.0.1",
            "localhost.",
            "localhost.attacker.example",
            "127.0.0.1.nip.io",
            "[::2]:8080",
            "::1",
            "127.0.0.1:99999",
            "127.0.0.1:+80",
            "127.0.0.1:80:80",
            "user@127.0.0.1",
            "",
            "machine.example.attacker",
        ] {
            assert!(!host_ok(&g, refused), "{refused} served");
        }
        // Two Host headers: refused; none (HTTP/1.0): served.
        let mut req = Request::builder()
            .header(header::HOST, "127.0.0.1")
            .header(header::HOST, "127.0.0.1")
            .body(axum::body::Body::empty())
            .unwrap();
        assert!(g.misdirected(&req).is_some());
        req.headers_mut().remove(header::HOST);
        assert!(g.misdirected(&req).is_none());
        // An absolute-form target names a host too.
        let req = Request::builder()
            .uri("http://attacker.example/api/v1/axes")
            .header(header::HOST, "127.0.0.1")
            .body(axum::body::Body::empty())
            .unwrap();
        assert!(g.misdirected(&req).is_some());
    }

    #[test]
    fn only_own_or_allowed_origins_pass() {
        let g = Guard {
            allowed_origins: vec!["http://localhost:5173".into()],
            ..Guard::default()
        };
        let own = [("host", "127.0.0.1:8080")];
        assert_eq!(
            g.cross_origin(&headers(&own)),
            None,
            "no Origin: curl, an MES"
        );
        for ok in [
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://127.0.0.1:8080"),
            ][..],
            &[("host", "localhost"), ("origin", "http://localhost")],
            &[("host", "localhost:80"), ("origin", "http://localhost")],
            // A Host without a port: the origin scheme's default (a TLS proxy in front).
            &[
                ("host", "machine.example"),
                ("origin", "https://machine.example"),
            ],
            &[
                ("host", "machine.example:443"),
                ("origin", "https://machine.example"),
            ],
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "https://127.0.0.1:8080"),
            ],
            &[
                ("host", "127.0.0.1:8080"),
                ("sec-fetch-site", "same-origin"),
            ],
            &[("host", "127.0.0.1:8080"), ("sec-fetch-site", "none")],
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://localhost:5173"),
            ],
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://localhost:5173"),
                ("sec-fetch-site", "same-site"),
            ],
        ] {
            assert_eq!(g.cross_origin(&headers(ok)), None, "{ok:?}");
        }
        for refused in [
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://evil.example"),
            ][..],
            &[("host", "127.0.0.1:8080"), ("origin", "null")],
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://127.0.0.1:8081"),
            ],
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://localhost:8080"),
            ],
            &[("host", "127.0.0.1:8080"), ("origin", "http://127.0.0.1")],
            &[
                ("host", "machine.example:80"),
                ("origin", "https://machine.example"),
            ],
            &[("origin", "http://127.0.0.1:8080")],
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://127.0.0.1:8080/"),
            ],
            &[("host", "127.0.0.1:8080"), ("sec-fetch-site", "cross-site")],
            &[("host", "127.0.0.1:8080"), ("sec-fetch-site", "same-site")],
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://127.0.0.1:8080"),
                ("sec-fetch-site", "cross-site"),
            ],
            &[
                ("host", "127.0.0.1:8080"),
                ("origin", "http://127.0.0.1:8080"),
                ("origin", "http://127.0.0.1:8080"),
            ],
        ] {
            assert!(g.cross_origin(&headers(refused)).is_some(), "{refused:?}");
        }
    }

    #[test]
    fn only_json_content_types_pass() {
        for ok in [
            "application/json",
            "application/json; charset=utf-8",
            "Application/JSON;charset=UTF-8",
        ] {
            assert!(
                json_content_type(&headers(&[("content-type", ok)])).is_ok(),
                "{ok}"
            );
        }
        for refused in [
            "text/plain",
            "text/plain; charset=application/json",
            "application/x-www-form-urlencoded",
            "multipart/form-data; boundary=x",
            "application/problem+json",
            "application/jsonx",
            "",
        ] {
            let h = headers(&[("content-type", refused)]);
            assert!(json_content_type(&h).is_err(), "{refused}");
        }
        assert!(json_content_type(&HeaderMap::new()).is_err());
        let two = [
            ("content-type", "application/json"),
            ("content-type", "application/json"),
        ];
        assert!(json_content_type(&headers(&two)).is_err());
    }

    #[test]
    fn options_are_checked_and_normalised() {
        assert_eq!(
            parse_public_name("Machine.Example").unwrap(),
            "machine.example"
        );
        assert_eq!(parse_public_name("192.168.0.10").unwrap(), "192.168.0.10");
        assert_eq!(parse_public_name("fd00::1").unwrap(), "[fd00::1]");
        assert_eq!(parse_public_name("[fd00::1]").unwrap(), "[fd00::1]");
        for bad in ["", "http://machine", "machine:8080", "machine/x", "a..b"] {
            assert!(parse_public_name(bad).is_err(), "{bad}");
        }
        assert_eq!(
            parse_allow_origin("http://localhost:5173").unwrap(),
            "http://localhost:5173"
        );
        assert_eq!(
            parse_allow_origin("HTTPS://Machine.Example:443/").unwrap(),
            "https://machine.example"
        );
        assert_eq!(
            parse_allow_origin("http://[::1]:80").unwrap(),
            "http://[::1]"
        );
        for bad in [
            "null",
            "*",
            "localhost:5173",
            "ftp://localhost",
            "http://",
            "http://localhost:5173/ui",
            "http://localhost:5173?x",
            "http://user@localhost",
        ] {
            assert!(parse_allow_origin(bad).is_err(), "{bad}");
        }
    }
}
