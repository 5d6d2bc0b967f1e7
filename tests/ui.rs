//! motiond serves the built commissioning UI at `/` (issue 4).

mod common;

use common::*;

async fn raw(s: &Server, path: &str) -> (u16, String, String, String) {
    let r = reqwest::get(s.url(path)).await.unwrap();
    let status = r.status().as_u16();
    let header = |name: &str| {
        r.headers()
            .get(name)
            .and_then(|v| v.to_str().ok())
            .unwrap_or_default()
            .to_string()
    };
    let ct = header("content-type");
    let cache = header("cache-control");
    (status, ct, cache, r.text().await.unwrap())
}

#[tokio::test(flavor = "multi_thread")]
async fn the_ui_directory_is_served_with_an_spa_fallback_and_the_api_untouched() {
    let dir = temp_dir();
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    let index = "<!doctype html><title>motiond-ui-test</title><div id=app></div>";
    std::fs::write(dir.join("index.html"), index).unwrap();
    std::fs::write(dir.join("assets/index-Ab12Cd34.js"), "console.log('ui')").unwrap();
    std::fs::write(dir.join("assets/index-Ef56Gh78.css"), "body{}").unwrap();
    std::fs::write(dir.join("robots.txt"), "User-agent: *").unwrap();
    let s = Server::start_with(":memory:", &["--ui-dir", dir.to_str().unwrap()]);
    assert!(
        s.log
            .lock()
            .unwrap()
            .iter()
            .any(|l| l.contains("commissioning UI: ") && l.contains(dir.to_str().unwrap())),
        "UI directory not logged"
    );

    let (status, ct, cache, body) = raw(&s, "/").await;
    assert_eq!((status, body.as_str()), (200, index));
    assert!(ct.starts_with("text/html"), "{ct}");
    assert_eq!(cache, "no-cache");

    let (status, ct, cache, body) = raw(&s, "/assets/index-Ab12Cd34.js").await;
    assert_eq!((status, body.as_str()), (200, "console.log('ui')"));
    assert!(ct.starts_with("text/javascript"), "{ct}");
    assert!(
        cache.contains("immutable") && cache.contains("max-age=31536000"),
        "{cache}"
    );
    let (status, ct, _, _) = raw(&s, "/assets/index-Ef56Gh78.css").await;
    assert_eq!(status, 200);
    assert!(ct.starts_with("text/css"), "{ct}");
    let (status, ct, cache, _) = raw(&s, "/robots.txt").await;
    assert_eq!(status, 200);
    assert!(ct.starts_with("text/plain"), "{ct}");
    assert_eq!(cache, "no-cache");

    // The app's own routes get index.html; a missing file is a 404, not HTML.
    for path in ["/scope", "/axes/x/parameters", "/index.html"] {
        let (status, ct, _, body) = raw(&s, path).await;
        assert_eq!((status, body.as_str()), (200, index), "{path}");
        assert!(ct.starts_with("text/html"), "{path}: {ct}");
    }
    assert_problem(
        &get(&s, "/assets/index-missing.js").await,
        404,
        "route_not_found",
    );
    assert_problem(&get(&s, "/../Cargo.toml").await, 404, "route_not_found");

    // The API, its documents and the metrics are not the UI's.
    assert_problem(&get(&s, "/api/v1/nope").await, 404, "route_not_found");
    assert_problem(&get(&s, "/api/nope").await, 404, "route_not_found");
    assert_problem(&get(&s, "/api").await, 404, "route_not_found");
    assert_eq!(get(&s, "/api/v1/axes").await.status, 200);
    let (status, ct, _, _) = raw(&s, "/metrics").await;
    assert_eq!(status, 200);
    assert!(ct.starts_with("text/plain"), "{ct}");
    let r = get(&s, "/openapi.json").await;
    assert_eq!(r.status, 200);
    assert!(r.json["paths"].is_object());
    let (status, ct, _, body) = raw(&s, "/docs/").await;
    assert_eq!(status, 200);
    assert!(
        ct.starts_with("text/html") && body.contains("swagger"),
        "{ct}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[tokio::test(flavor = "multi_thread")]
async fn a_missing_ui_directory_answers_how_to_build_it() {
    let dir = temp_dir().join("not-built");
    let s = Server::start_with(":memory:", &["--ui-dir", dir.to_str().unwrap()]);
    assert!(
        s.log
            .lock()
            .unwrap()
            .iter()
            .any(|l| l.contains("UI not built")),
        "missing UI not logged"
    );
    for path in ["/", "/scope"] {
        let (status, ct, _, body) = raw(&s, path).await;
        assert_eq!(status, 200, "{path}");
        assert!(ct.starts_with("text/html"), "{ct}");
        assert!(body.contains("not built"), "{body}");
        assert!(
            body.contains("npm --prefix frontend ci &amp;&amp; npm --prefix frontend run build"),
            "{body}"
        );
    }
    assert_problem(
        &get(&s, "/assets/index-Ab12Cd34.js").await,
        404,
        "route_not_found",
    );
    assert_eq!(get(&s, "/api/v1/system").await.status, 200);
}
