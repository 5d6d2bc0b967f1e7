//! The role each route needs: the classes of routes, and each block's role from its
//! catalogue entry. The request check (`api::auth::check_role`) and the OpenAPI document's
//! `security` of every operation (`api::errors`) both read it.

use axum::http::Method;

use crate::auth::Role;

/// The role a request needs, from its method and route (the matched path, with `{axis}` …);
/// `None`: public (the UI's files, the documents, login, logout and the session query).
/// The OpenAPI document's `security` of every operation is made from this function too.
pub fn required(method: &Method, path: &str) -> Option<Role> {
    use Role::*;
    if path == "/metrics" {
        return Some(Viewer);
    }
    let p = path.strip_prefix("/api/v1")?;
    let read = method == Method::GET || method == Method::HEAD;
    Some(match p {
        "/auth/login" | "/auth/logout" | "/auth/session" => return None,
        "/auth/password" => Viewer,
        _ if p.starts_with("/users") || p.starts_with("/tokens") => Admin,
        "/audit" => Engineer,
        // A computation that stores nothing: whoever may read the tables may analyse one.
        "/cam-analysis" | "/path-analysis" => Viewer,
        _ if read => Viewer,
        "/control" => Operator,
        // Running the virtual clock moves what was commanded, as a command would.
        "/clock/advance" => Operator,
        "/commands/{id}" | "/commands/{id}/keepalive" | "/commands/{id}/inputs" => Operator,
        "/axes/{axis}/status/following-error-peak/reset" => Operator,
        // The external setpoint generator's samples, fed like a jog's keepalives.
        "/axes/{axis}/ext-setpoint-gen-feed" => Operator,
        _ if p.starts_with("/scope/") => Operator,
        _ if p.starts_with("/groups/{group}/") => match p
            .strip_prefix("/groups/{group}/")
            .and_then(|n| super::blocks::find(super::blocks::At::Groups, n))
        {
            Some(block) => block.role,
            None => Engineer,
        },
        _ => match p
            .strip_prefix("/axes/{axis}/")
            .and_then(|n| super::blocks::find(super::blocks::At::Axes, n))
        {
            Some(block) => block.role,
            // Axes, parameters, cam tables, configuration, fault injection.
            None => Engineer,
        },
    })
}

/// The answers of the request checks (`guard.rs`), added to every operation by the rule the
/// checks follow: 421 to all, 403 and 415 to those that change something; and the role each
/// needs ([`required`]): its `security`, `x-motiond-role`, 401 and 403.
pub struct RequestChecks;

impl utoipa::Modify for RequestChecks {
    fn modify(&self, doc: &mut utoipa::openapi::OpenApi) {
        use axum::http::Method;
        use utoipa::openapi::security::{
            ApiKey, ApiKeyValue, Http, HttpAuthScheme, SecurityRequirement, SecurityScheme,
        };
        use utoipa::openapi::{Ref, RefOr};
        let response = |name: &str| RefOr::Ref(Ref::from_response_name(name));
        let components = doc.components.get_or_insert_with(Default::default);
        components.security_schemes.insert(
            "bearer".into(),
            SecurityScheme::Http(
                Http::builder()
                    .scheme(HttpAuthScheme::Bearer)
                    .description(Some("An API token (`POST /api/v1/tokens`), for machines"))
                    .build(),
            ),
        );
        components.security_schemes.insert(
            "session".into(),
            SecurityScheme::ApiKey(ApiKey::Cookie(ApiKeyValue::with_description(
                crate::auth::COOKIE,
                "The browser session of `POST /api/v1/auth/login`",
            ))),
        );
        for (path, item) in doc.paths.paths.iter_mut() {
            let ops = [
                (Method::GET, &mut item.get, false),
                (Method::HEAD, &mut item.head, false),
                (Method::OPTIONS, &mut item.options, false),
                (Method::TRACE, &mut item.trace, false),
                (Method::POST, &mut item.post, true),
                (Method::PUT, &mut item.put, true),
                (Method::PATCH, &mut item.patch, true),
                (Method::DELETE, &mut item.delete, true),
            ];
            for (method, op, changes) in ops {
                let Some(op) = op.as_mut() else { continue };
                let role = required(&method, path);
                let responses = &mut op.responses.responses;
                responses.insert("421".into(), response("MisdirectedRequest"));
                if changes {
                    let forbidden = if role.is_some() {
                        "Forbidden"
                    } else {
                        "CrossOriginForbidden"
                    };
                    responses.insert("403".into(), response(forbidden));
                    responses.insert("415".into(), response("UnsupportedMediaType"));
                }
                // None: public, no credentials needed.
                if let Some(role) = role {
                    responses.insert("401".into(), response("Unauthenticated"));
                    if !changes {
                        responses.insert("403".into(), response("RoleInsufficient"));
                    }
                    op.security = Some(vec![
                        SecurityRequirement::new("bearer", Vec::<String>::new()),
                        SecurityRequirement::new("session", Vec::<String>::new()),
                    ]);
                    // A block names its role in `x-motiond-block` already (and utoipa
                    // writes several extensions in no fixed order).
                    let ext = op.extensions.get_or_insert_with(Default::default);
                    if !ext.contains_key("x-motiond-block") {
                        ext.insert("x-motiond-role".into(), serde_json::json!(role));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn routes_need_the_roles_of_their_class() {
        use Role::*;
        let r = |m: Method, p: &str| required(&m, p);
        assert_eq!(r(Method::GET, "/"), None);
        assert_eq!(r(Method::GET, "/openapi.json"), None);
        assert_eq!(r(Method::POST, "/api/v1/auth/login"), None);
        assert_eq!(r(Method::GET, "/metrics"), Some(Viewer));
        assert_eq!(r(Method::GET, "/api/v1/axes/{axis}/status"), Some(Viewer));
        assert_eq!(r(Method::GET, "/api/v1/ws"), Some(Viewer));
        assert_eq!(
            r(Method::POST, "/api/v1/axes/{axis}/move-absolute"),
            Some(Operator)
        );
        assert_eq!(r(Method::POST, "/api/v1/axes/{axis}/stop"), Some(Operator));
        assert_eq!(
            r(Method::POST, "/api/v1/groups/{group}/move-path"),
            Some(Operator)
        );
        assert_eq!(r(Method::POST, "/api/v1/groups"), Some(Engineer));
        assert_eq!(r(Method::PUT, "/api/v1/groups/{group}"), Some(Engineer));
        assert_eq!(
            r(Method::POST, "/api/v1/axes/{axis}/simulation/fault"),
            Some(Engineer)
        );
        assert_eq!(
            r(Method::PUT, "/api/v1/axes/{axis}/parameters/{parameter}"),
            Some(Engineer)
        );
        assert_eq!(r(Method::PUT, "/api/v1/config"), Some(Engineer));
        assert_eq!(r(Method::GET, "/api/v1/audit"), Some(Engineer));
        assert_eq!(r(Method::POST, "/api/v1/scope/recordings"), Some(Operator));
        assert_eq!(r(Method::POST, "/api/v1/control"), Some(Operator));
        assert_eq!(r(Method::GET, "/api/v1/users"), Some(Admin));
        assert_eq!(r(Method::DELETE, "/api/v1/tokens/{id}"), Some(Admin));
    }
}
