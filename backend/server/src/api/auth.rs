//! Login and logout, users, API tokens, the role check of every request, and the control of
//! the machine (`/api/v1/control`).

use std::sync::Arc;

use axum::Json;
use axum::extract::{MatchedPath, Path, Request, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::{Client, JsonBody};
use crate::app::AppState;
use crate::auth::{self, NewToken, Role, TokenView, UserView};
use crate::error::{AppError, AppResult};
use crate::service::audit_entry;
use crate::service::control::{ControlState, TakeControl};

/// Every routed request: the role its route needs ([`super::roles::required`]) against the client's
/// credentials, while authentication is enabled. The principal goes into the request for the
/// handlers (the audit log names it).
pub async fn check_role(State(s): State<Arc<AppState>>, mut req: Request, next: Next) -> Response {
    let path = req
        .extensions()
        .get::<MatchedPath>()
        .map(|m| m.as_str().to_owned())
        .unwrap_or_else(|| req.uri().path().to_owned());
    let Some(need) = super::roles::required(req.method(), &path) else {
        return next.run(req).await;
    };
    match s.auth.authorize(req.headers(), need) {
        Ok(Some(p)) => {
            req.extensions_mut().insert(p);
            next.run(req).await
        }
        Ok(None) => next.run(req).await,
        Err(e) => {
            let mut r = e.into_response();
            if r.status() == StatusCode::UNAUTHORIZED {
                r.headers_mut().insert(
                    header::WWW_AUTHENTICATE,
                    HeaderValue::from_static("Bearer realm=\"motiond\""),
                );
            }
            r
        }
    }
}

/// `POST /auth/login`.
#[derive(Deserialize, ToSchema)]
#[schema(example = json!({"name": "anna", "password": "correct horse battery"}))]
#[serde(deny_unknown_fields)]
pub struct Login {
    #[schema(example = "anna", min_length = 1, max_length = 64)]
    pub name: String,
    #[schema(example = "correct horse battery", min_length = 1, max_length = 1024)]
    pub password: String,
}

/// Who the client is.
#[derive(Serialize, ToSchema)]
#[schema(example = json!({"auth_enabled": true, "principal": "user:anna", "name": "anna", "kind": "user",
    "role": "engineer", "expires_at": "2026-11-25T20:00:00.000Z"}))]
pub struct SessionState {
    /// False: no user exists yet, every client may do everything (loopback only).
    pub auth_enabled: bool,
    /// `user:NAME` or `token:NAME`; null when not authenticated.
    pub principal: Option<String>,
    pub name: Option<String>,
    /// `user` (browser session) or `token`.
    pub kind: Option<String>,
    pub role: Option<Role>,
    /// When the session ends (null for tokens and when not authenticated).
    pub expires_at: Option<String>,
}

fn session_state(s: &AppState, p: Option<&auth::Principal>) -> SessionState {
    SessionState {
        auth_enabled: s.auth.enabled(),
        principal: p.map(|p| p.label()),
        name: p.map(|p| p.name.clone()),
        kind: p.map(|p| {
            match p.kind {
                auth::PrincipalKind::User => "user",
                auth::PrincipalKind::Token => "token",
            }
            .to_owned()
        }),
        role: p.map(|p| p.role),
        expires_at: p
            .and_then(|p| s.auth.session_expiry(p))
            .map(|t| humantime::format_rfc3339_millis(t).to_string()),
    }
}

#[utoipa::path(get, path = "/api/v1/auth/session", tag = "auth",
    summary = "Who am I: whether authentication is enabled, and the client's user or token and role",
    description = "Public. A session cookie or token that is no longer valid is a 401.",
    responses((status = 200, body = SessionState), super::errors::SessionErrors))]
pub async fn session(
    State(s): State<Arc<AppState>>,
    headers: HeaderMap,
) -> AppResult<Json<SessionState>> {
    let p = s.auth.authenticate(&headers)?;
    Ok(Json(session_state(&s, p.as_ref())))
}

#[utoipa::path(post, path = "/api/v1/auth/login", tag = "auth",
    summary = "Log in: a browser session (HttpOnly, SameSite=Strict cookie `motiond_session`; Secure over TLS)",
    description = "Five wrong passwords for a name lock it for 30 s (429). Machines use API tokens instead.",
    request_body = Login,
    responses((status = 200, body = SessionState,
        headers(("Set-Cookie" = String, description = "motiond_session=…; Path=/; HttpOnly; SameSite=Strict; Max-Age=…"))),
        super::errors::LoginErrors))]
pub async fn login(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(body, _): JsonBody<Login>,
) -> AppResult<Response> {
    if !s.auth.enabled() {
        return Err(AppError::conflict(
            "authentication_disabled",
            "no user exists: authentication is off (create an admin with `motiond user add --admin NAME`)",
        ));
    }
    let result = s.auth.login(&body.name, &body.password).await;
    let mut audit = audit_entry(&client.0, "auth.login", &body.name, String::new());
    audit.outcome = Some(match &result {
        Ok(_) => "accepted".into(),
        Err(e) => format!("rejected:{}", e.problem().code),
    });
    // Named only once the password proved who it is.
    audit.principal = result.is_ok().then(|| format!("user:{}", body.name));
    s.audit(audit);
    let new = result?;
    let ttl = new
        .expires
        .duration_since(std::time::SystemTime::now())
        .unwrap_or_default();
    let state = SessionState {
        auth_enabled: true,
        principal: Some(format!("user:{}", new.user.name)),
        name: Some(new.user.name.clone()),
        kind: Some("user".into()),
        role: Some(new.user.role),
        expires_at: Some(humantime::format_rfc3339_millis(new.expires).to_string()),
    };
    let mut r = Json(state).into_response();
    let cookie = auth::set_cookie(Some((&new.secret, ttl)), s.auth.tls);
    r.headers_mut().insert(
        header::SET_COOKIE,
        HeaderValue::from_str(&cookie).expect("ascii"),
    );
    Ok(r)
}

#[utoipa::path(post, path = "/api/v1/auth/logout", tag = "auth",
    summary = "Log out: ends the session of the cookie sent and clears it (204 also without one)",
    responses((status = 204, description = "Logged out",
        headers(("Set-Cookie" = String, description = "motiond_session=; Max-Age=0 …"))), super::errors::LogoutErrors))]
pub async fn logout(State(s): State<Arc<AppState>>, headers: HeaderMap) -> AppResult<Response> {
    if let Some(cookie) = auth::session_cookie(&headers) {
        s.auth.logout(cookie).await?;
    }
    let mut r = StatusCode::NO_CONTENT.into_response();
    r.headers_mut().insert(
        header::SET_COOKIE,
        HeaderValue::from_str(&auth::set_cookie(None, s.auth.tls)).expect("ascii"),
    );
    Ok(r)
}

/// `PUT /auth/password`.
#[derive(Deserialize, ToSchema)]
#[schema(example = json!({"current_password": "correct horse battery", "new_password": "staple battery horse"}))]
#[serde(deny_unknown_fields)]
pub struct PasswordChange {
    #[schema(min_length = 1, max_length = 1024)]
    pub current_password: String,
    /// 8–1024 characters.
    #[schema(min_length = 8, max_length = 1024)]
    pub new_password: String,
}

#[utoipa::path(put, path = "/api/v1/auth/password", tag = "auth",
    summary = "Change one's own password (a logged-in user); ends the user's other sessions",
    request_body = PasswordChange,
    responses((status = 200, body = UserView), super::errors::PasswordErrors))]
pub async fn change_password(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(body, _): JsonBody<PasswordChange>,
) -> AppResult<Json<UserView>> {
    let Some(p) = client.0.identity.clone() else {
        return Err(AppError::conflict(
            "authentication_disabled",
            "no user exists: authentication is off",
        ));
    };
    if p.kind != auth::PrincipalKind::User {
        return Err(AppError::conflict(
            "not_a_user",
            "an API token has no password: log in as a user",
        ));
    }
    s.auth
        .verify(&p.name, &body.current_password)
        .await
        .map_err(|e| match e.status() {
            StatusCode::UNAUTHORIZED => AppError::field("current_password", "is wrong"),
            _ => e,
        })?;
    let audit = audit_entry(&client.0, "user.password", &p.name, String::new());
    let v = s
        .auth
        .update_user(&p.name, None, Some(&body.new_password), Some(&p), audit)
        .await?;
    Ok(Json(v))
}

/// `POST /users`.
#[derive(Deserialize, ToSchema)]
#[schema(example = json!({"name": "bert", "role": "operator", "password": "bert-on-shift-2"}))]
#[serde(deny_unknown_fields)]
pub struct NewUser {
    /// 1–64 letters, digits and `.-_@`.
    #[schema(
        example = "anna",
        min_length = 1,
        max_length = 64,
        pattern = "^[A-Za-z0-9._@-]{1,64}$"
    )]
    pub name: String,
    pub role: Role,
    /// 8–1024 characters.
    #[schema(min_length = 8, max_length = 1024)]
    pub password: String,
}

/// `PUT /users/{name}`: what to change.
#[derive(Deserialize, ToSchema)]
#[schema(example = json!({"role": "engineer"}))]
#[serde(deny_unknown_fields)]
pub struct UserChange {
    pub role: Option<Role>,
    /// A new password (8–1024 characters); ends the user's sessions.
    #[schema(min_length = 8, max_length = 1024)]
    pub password: Option<String>,
}

#[utoipa::path(get, path = "/api/v1/users", tag = "auth", summary = "The users (admin)",
    responses((status = 200, body = Vec<UserView>)))]
pub async fn list_users(State(s): State<Arc<AppState>>) -> Json<Vec<UserView>> {
    Json(s.auth.users())
}

#[utoipa::path(post, path = "/api/v1/users", tag = "auth",
    summary = "Create a user (admin). The first user must be an admin: it turns authentication on",
    request_body = NewUser,
    responses((status = 201, body = UserView, headers(("Location" = String, description = "/api/v1/users/{name}"))),
        super::errors::UserCreateErrors))]
pub async fn create_user(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(body, _): JsonBody<NewUser>,
) -> AppResult<Response> {
    let audit = audit_entry(
        &client.0,
        "user.create",
        &body.name,
        serde_json::json!({"role": body.role}).to_string(),
    );
    let v = s
        .auth
        .add_user(&body.name, body.role, &body.password, audit)
        .await?;
    let mut r = (StatusCode::CREATED, Json(&v)).into_response();
    if let Ok(loc) = HeaderValue::from_str(&format!("/api/v1/users/{}", v.name)) {
        r.headers_mut().insert(header::LOCATION, loc);
    }
    Ok(r)
}

#[utoipa::path(get, path = "/api/v1/users/{name}", tag = "auth", summary = "One user (admin)",
    params(("name" = String, Path, description = "user name")),
    responses((status = 200, body = UserView), super::errors::UserReadErrors))]
pub async fn get_user(
    State(s): State<Arc<AppState>>,
    Path(name): Path<String>,
) -> AppResult<Json<UserView>> {
    s.auth
        .user(&name)
        .map(Json)
        .ok_or_else(|| AppError::not_found("user", &name))
}

#[utoipa::path(put, path = "/api/v1/users/{name}", tag = "auth",
    summary = "Change a user's role or password (admin); a new password ends the user's sessions",
    params(("name" = String, Path, description = "user name")),
    request_body = UserChange,
    responses((status = 200, body = UserView), super::errors::UserChangeErrors))]
pub async fn update_user(
    State(s): State<Arc<AppState>>,
    Path(name): Path<String>,
    client: Client,
    JsonBody(body, _): JsonBody<UserChange>,
) -> AppResult<Json<UserView>> {
    let audit = audit_entry(
        &client.0,
        "user.update",
        &name,
        serde_json::json!({"role": body.role, "password": body.password.is_some()}).to_string(),
    );
    let keep = client.0.identity.as_ref().filter(|p| p.name == name);
    s.auth
        .update_user(&name, body.role, body.password.as_deref(), keep, audit)
        .await
        .map(Json)
}

#[utoipa::path(delete, path = "/api/v1/users/{name}", tag = "auth",
    summary = "Delete a user and end its sessions (admin); never the last admin",
    params(("name" = String, Path, description = "user name")),
    responses((status = 204, description = "Deleted"), super::errors::UserDeleteErrors))]
pub async fn delete_user(
    State(s): State<Arc<AppState>>,
    Path(name): Path<String>,
    client: Client,
) -> AppResult<StatusCode> {
    let audit = audit_entry(&client.0, "user.delete", &name, String::new());
    s.auth.delete_user(&name, audit).await?;
    Ok(StatusCode::NO_CONTENT)
}

/// `POST /tokens`.
#[derive(Deserialize, ToSchema)]
#[schema(example = json!({"name": "line-3-mes", "role": "operator", "expires_in_days": 365}))]
#[serde(deny_unknown_fields)]
pub struct TokenRequest {
    /// Names the token in the audit log (`token:NAME`): 1–64 letters, digits and `.-_@`.
    #[schema(
        example = "line-3-mes",
        min_length = 1,
        max_length = 64,
        pattern = "^[A-Za-z0-9._@-]{1,64}$"
    )]
    pub name: String,
    pub role: Role,
    /// Days until it expires (1–3650); never when left out.
    #[schema(minimum = 1, maximum = 3650)]
    pub expires_in_days: Option<u32>,
}

#[utoipa::path(get, path = "/api/v1/tokens", tag = "auth",
    summary = "The API tokens, revoked ones too (admin); never their secrets",
    responses((status = 200, body = Vec<TokenView>)))]
pub async fn list_tokens(State(s): State<Arc<AppState>>) -> Json<Vec<TokenView>> {
    Json(s.auth.tokens())
}

#[utoipa::path(post, path = "/api/v1/tokens", tag = "auth",
    summary = "Create an API token for a machine (admin): its secret is in this answer only",
    request_body = TokenRequest,
    responses((status = 201, body = NewToken), super::errors::TokenCreateErrors))]
pub async fn create_token(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(body, _): JsonBody<TokenRequest>,
) -> AppResult<Response> {
    if body
        .expires_in_days
        .is_some_and(|d| !(1..=3650).contains(&d))
    {
        return Err(AppError::field("expires_in_days", "must be 1 to 3650"));
    }
    let by = client
        .0
        .principal
        .clone()
        .unwrap_or_else(|| format!("client {}", client.0.addr));
    let audit = audit_entry(
        &client.0,
        "token.create",
        &body.name,
        serde_json::json!({"role": body.role, "expires_in_days": body.expires_in_days}).to_string(),
    );
    let t = s
        .auth
        .add_token(&body.name, body.role, body.expires_in_days, &by, audit)
        .await?;
    let mut r = (StatusCode::CREATED, Json(t)).into_response();
    // The secret must not be kept by caches on the way.
    r.headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    Ok(r)
}

#[utoipa::path(delete, path = "/api/v1/tokens/{id}", tag = "auth",
    summary = "Revoke an API token (admin): refused from now on; it stays listed",
    params(("id" = i64, Path, description = "token id")),
    responses((status = 200, body = TokenView), super::errors::TokenRevokeErrors))]
pub async fn revoke_token(
    State(s): State<Arc<AppState>>,
    Path(id): Path<String>,
    client: Client,
) -> AppResult<Json<TokenView>> {
    let id: i64 = id.parse().map_err(|_| AppError::not_found("token", &id))?;
    let audit = audit_entry(&client.0, "token.revoke", &id.to_string(), String::new());
    s.auth.revoke_token(id, audit).await.map(Json)
}

#[utoipa::path(get, path = "/api/v1/control", tag = "control",
    summary = "Who holds control of the machine (one holder commands motion at a time)",
    responses((status = 200, body = ControlState)))]
pub async fn get_control(State(s): State<Arc<AppState>>, client: Client) -> Json<ControlState> {
    Json(s.control.state(&client.0))
}

#[utoipa::path(post, path = "/api/v1/control", tag = "control",
    summary = "Take or renew control of the machine for `lease_ms`",
    description = "While a client holds control, motion commands of every other client are refused with \
409 `control_held` (stop, halt and power with `enable: false` are always accepted). The holder renews by sending this \
again before the lease ends; a lease not renewed ends by itself. A client is known by its user or token and its \
`X-Client-Id` header (which it must send while authentication is off). `take_over: true` takes control from another \
holder: admins only (anyone while authentication is off).",
    request_body = TakeControl,
    responses((status = 200, body = ControlState), super::errors::ControlErrors))]
pub async fn take_control(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(body, raw): JsonBody<TakeControl>,
) -> AppResult<Json<ControlState>> {
    let r = s.control.take(&client.0, &body);
    let renewal = matches!(r, Ok((_, false)));
    if !renewal {
        let mut a = audit_entry(&client.0, "control.take", "machine", raw.to_string());
        a.outcome = Some(match &r {
            Ok(_) => "accepted".into(),
            Err(e) => format!("rejected:{}", e.problem().code),
        });
        s.audit(a);
    }
    r.map(|(state, _)| Json(state))
}

#[utoipa::path(delete, path = "/api/v1/control", tag = "control",
    summary = "Give control back (its holder, or an admin)",
    responses((status = 200, body = ControlState), super::errors::ControlReleaseErrors))]
pub async fn release_control(
    State(s): State<Arc<AppState>>,
    client: Client,
) -> AppResult<Json<ControlState>> {
    if s.control.release(&client.0)? {
        s.audit(audit_entry(
            &client.0,
            "control.release",
            "machine",
            String::new(),
        ));
    }
    Ok(Json(s.control.state(&client.0)))
}
