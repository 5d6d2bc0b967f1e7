//! Who is asking, and may they (DESIGN §6): users with argon2id password hashes, browser
//! sessions (an HttpOnly cookie), API tokens for machines (`Authorization: Bearer`), and the
//! roles (the role each route needs is the API's: `api::roles::required`).
//!
//! Authentication is enabled as soon as one user exists (created with `motiond user add`, on
//! first start from `MOTIOND_ADMIN_USER` / `MOTIOND_ADMIN_PASSWORD`, or through the API);
//! a machine without users answers every client as today, on loopback only (decision 86).
//!
//! Users, live sessions and tokens are kept in memory and written through to SQLite, so that
//! checking a request reads no database. Secrets are never stored: a session id or token is 32
//! random bytes, stored as its SHA-256; a password as an argon2id PHC string.

use std::collections::{BTreeMap, HashMap};
use std::sync::{Mutex, RwLock};
use std::time::{Duration, Instant, SystemTime};

use axum::http::{HeaderMap, StatusCode, header};
use base64::Engine;
use serde::{Deserialize, Serialize};
use sqlx::SqlitePool;
use utoipa::ToSchema;

use crate::error::{AppError, AppResult};
use crate::store;

/// What a client must be allowed to do. Ordered: each role may do what the ones before it may.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize, ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// Reads status, configuration and recordings.
    Viewer,
    /// Moves axes: every motion and coupling block, power, reset, control of the machine,
    /// scope recordings.
    Operator,
    /// Changes what the machine is: axes, parameters, cam tables, configuration import, fault
    /// injection; reads the audit log.
    Engineer,
    /// Users and tokens; takes control over from another holder.
    Admin,
}

impl Role {
    pub fn as_str(self) -> &'static str {
        match self {
            Role::Viewer => "viewer",
            Role::Operator => "operator",
            Role::Engineer => "engineer",
            Role::Admin => "admin",
        }
    }
    pub fn parse(s: &str) -> Option<Role> {
        Some(match s {
            "viewer" => Role::Viewer,
            "operator" => Role::Operator,
            "engineer" => Role::Engineer,
            "admin" => Role::Admin,
            _ => return None,
        })
    }
}

/// An authenticated client: a user (by session) or an API token.
#[derive(Clone, Debug)]
pub struct Principal {
    pub kind: PrincipalKind,
    pub name: String,
    pub role: Role,
    /// The SHA-256 of the session id or token (to check it is still valid later, e.g. on a
    /// websocket opened with it).
    secret: [u8; 32],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrincipalKind {
    User,
    Token,
}

impl Principal {
    /// `user:NAME` or `token:NAME`: how the audit log and the control holder name it.
    pub fn label(&self) -> String {
        match self.kind {
            PrincipalKind::User => format!("user:{}", self.name),
            PrincipalKind::Token => format!("token:{}", self.name),
        }
    }
}

/// The session cookie's name.
pub const COOKIE: &str = "motiond_session";
/// Tokens start with this, so that a leaked one is recognisable (secret scanners).
pub const TOKEN_PREFIX: &str = "mtk_";
/// Failed logins of one name before it is locked for [`LOCKOUT`].
const MAX_FAILURES: u32 = 5;
const LOCKOUT: Duration = Duration::from_secs(30);

struct User {
    id: i64,
    name: String,
    role: Role,
    password_hash: String,
    created_at: String,
}

struct Session {
    user_id: i64,
    expires: SystemTime,
}

struct Token {
    id: i64,
    name: String,
    role: Role,
    secret: [u8; 32],
    created_by: String,
    created_at: String,
    expires: Option<SystemTime>,
    last_used: Option<SystemTime>,
    /// When `last_used` was last written to the database (at most once a minute per token).
    last_written: Option<Instant>,
    revoked: Option<String>,
}

#[derive(Default)]
struct Books {
    users: BTreeMap<i64, User>,
    sessions: HashMap<[u8; 32], Session>,
    tokens: Vec<Token>,
}

/// A user as the API shows it.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"name": "anna", "role": "engineer", "created_at": "2026-11-25T08:00:00.000Z"}))]
pub struct UserView {
    pub name: String,
    pub role: Role,
    pub created_at: String,
}

/// An API token as the API shows it (never its secret, except once in [`NewToken`]).
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"id": 3, "name": "line-3-mes", "role": "operator", "created_by": "user:anna",
    "created_at": "2026-11-25T08:00:00.000Z", "expires_at": null, "last_used_at": "2026-11-25T09:12:40.000Z", "revoked_at": null}))]
pub struct TokenView {
    pub id: i64,
    pub name: String,
    pub role: Role,
    /// `user:NAME` of the admin who made it.
    pub created_by: String,
    pub created_at: String,
    pub expires_at: Option<String>,
    /// Written at most once a minute.
    pub last_used_at: Option<String>,
    pub revoked_at: Option<String>,
}

/// A new token: the only time its secret is shown.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"id": 3, "name": "line-3-mes", "role": "operator", "created_by": "user:anna",
    "created_at": "2026-11-25T08:00:00.000Z", "expires_at": null, "last_used_at": null, "revoked_at": null,
    "token": "mtk_Yp3M0kq8rYdJ2tNwq6mC6Wb1dV8yO2uZ3nKXh5s0aQc"}))]
pub struct NewToken {
    #[serde(flatten)]
    pub view: TokenView,
    /// Send as `Authorization: Bearer <token>`. Shown once; motiond keeps only its hash.
    #[schema(example = "mtk_Yp3M0kq8rYdJ2tNwq6mC6Wb1dV8yO2uZ3nKXh5s0aQc")]
    pub token: String,
}

/// What `motiond` knows of a login.
pub struct NewSession {
    /// The cookie's value.
    pub secret: String,
    pub expires: SystemTime,
    pub user: UserView,
}

/// The authentication state of the server.
pub struct Auth {
    db: SqlitePool,
    books: RwLock<Books>,
    /// Failed logins per name: how many, and when the last was.
    failures: Mutex<HashMap<String, (u32, Instant)>>,
    /// How long a browser session lasts from its login.
    pub session_ttl: Duration,
    /// Served over TLS: the session cookie is `Secure`.
    pub tls: bool,
}

fn random32() -> [u8; 32] {
    use ring::rand::SecureRandom;
    let mut b = [0u8; 32];
    ring::rand::SystemRandom::new()
        .fill(&mut b)
        .expect("the system's random source works");
    b
}

fn sha256(b: &[u8]) -> [u8; 32] {
    let d = ring::digest::digest(&ring::digest::SHA256, b);
    d.as_ref().try_into().expect("32 bytes")
}

fn b64(b: &[u8]) -> String {
    base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(b)
}

fn rfc3339(t: SystemTime) -> String {
    humantime::format_rfc3339_millis(t).to_string()
}

fn parse_time(s: &str) -> Option<SystemTime> {
    humantime::parse_rfc3339_weak(s).ok()
}

/// An argon2id hash (the crate's defaults: 19 MiB, 2 passes, OWASP's minimum) of a password.
pub fn hash_password(password: &str) -> Result<String, String> {
    use argon2::password_hash::{PasswordHasher, SaltString};
    let salt = SaltString::encode_b64(&random32()[..16]).map_err(|e| e.to_string())?;
    argon2::Argon2::default()
        .hash_password(password.as_bytes(), &salt)
        .map(|h| h.to_string())
        .map_err(|e| e.to_string())
}

fn verify_password(password: &str, hash: &str) -> bool {
    use argon2::password_hash::{PasswordHash, PasswordVerifier};
    PasswordHash::new(hash).is_ok_and(|h| {
        argon2::Argon2::default()
            .verify_password(password.as_bytes(), &h)
            .is_ok()
    })
}

/// A user or token name: 1–64 characters of letters, digits and `.-_@`.
pub fn check_name(field: &str, name: &str) -> AppResult<()> {
    let ok = !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_' | '@'));
    if ok {
        Ok(())
    } else {
        Err(AppError::field(
            field,
            "must be 1-64 characters of letters, digits and . - _ @",
        ))
    }
}

/// A password: 8–1024 characters.
pub fn check_password(field: &str, password: &str) -> AppResult<()> {
    let n = password.chars().count();
    if (8..=1024).contains(&n) {
        Ok(())
    } else {
        Err(AppError::field(field, "must be 8 to 1024 characters"))
    }
}

/// The audit row of a change, then the commit of its transaction: both or neither.
async fn audit_and_commit(
    mut tx: sqlx::Transaction<'_, sqlx::Sqlite>,
    audit: &store::AuditEntry,
) -> AppResult<()> {
    store::audit(&mut *tx, audit)
        .await
        .map_err(AppError::storage)?;
    tx.commit().await.map_err(AppError::storage)
}

/// A storage error, or the 409 `code` when it is a UNIQUE violation (the name is taken).
fn taken(e: sqlx::Error, code: &'static str, detail: String) -> AppError {
    match &e {
        sqlx::Error::Database(d) if d.is_unique_violation() => AppError::conflict(code, detail),
        _ => AppError::storage(e),
    }
}

/// The argon2id hash of a password, on a blocking thread (it takes tens of ms by design).
async fn hash_off_thread(password: &str) -> AppResult<String> {
    let pw = password.to_owned();
    tokio::task::spawn_blocking(move || hash_password(&pw))
        .await
        .map_err(|e| AppError::unavailable("hash_failed", e.to_string()))?
        .map_err(|e| AppError::unavailable("hash_failed", e))
}

fn unauthenticated(detail: impl Into<String>) -> AppError {
    AppError::new(
        StatusCode::UNAUTHORIZED,
        "unauthenticated",
        "Authentication required",
        detail,
    )
}

fn invalid_credentials(detail: impl Into<String>) -> AppError {
    AppError::new(
        StatusCode::UNAUTHORIZED,
        "invalid_credentials",
        "Invalid credentials",
        detail,
    )
}

/// 403: authenticated, but the role is too low.
pub fn forbidden(who: &Principal, need: Role) -> AppError {
    AppError::new(
        StatusCode::FORBIDDEN,
        "role_insufficient",
        "Forbidden",
        format!(
            "this needs the role {} or higher; {} has the role {}",
            need.as_str(),
            who.label(),
            who.role.as_str()
        ),
    )
}

impl Auth {
    /// Loads users, unexpired sessions and tokens.
    pub async fn load(db: SqlitePool, session_ttl: Duration, tls: bool) -> Result<Auth, String> {
        let now = SystemTime::now();
        store::auth::delete_expired_sessions(&db, &rfc3339(now))
            .await
            .map_err(|e| format!("cannot read the sessions: {e}"))?;
        let mut books = Books::default();
        for u in store::auth::users(&db)
            .await
            .map_err(|e| format!("cannot read the users: {e}"))?
        {
            let role = Role::parse(&u.role).unwrap_or(Role::Viewer);
            books.users.insert(
                u.id,
                User {
                    id: u.id,
                    name: u.name,
                    role,
                    password_hash: u.password_hash,
                    created_at: u.created_at,
                },
            );
        }
        for s in store::auth::sessions(&db)
            .await
            .map_err(|e| format!("cannot read the sessions: {e}"))?
        {
            let (Ok(secret), Some(expires)) = (
                <[u8; 32]>::try_from(s.secret_sha256),
                parse_time(&s.expires_at),
            ) else {
                continue;
            };
            books.sessions.insert(
                secret,
                Session {
                    user_id: s.user_id,
                    expires,
                },
            );
        }
        for t in store::auth::tokens(&db)
            .await
            .map_err(|e| format!("cannot read the API tokens: {e}"))?
        {
            let Ok(secret) = <[u8; 32]>::try_from(t.secret_sha256) else {
                continue;
            };
            books.tokens.push(Token {
                id: t.id,
                name: t.name,
                role: Role::parse(&t.role).unwrap_or(Role::Viewer),
                secret,
                created_by: t.created_by,
                created_at: t.created_at,
                expires: t.expires_at.as_deref().and_then(parse_time),
                last_used: t.last_used_at.as_deref().and_then(parse_time),
                last_written: None,
                revoked: t.revoked_at,
            });
        }
        Ok(Auth {
            db,
            books: RwLock::new(books),
            failures: Mutex::new(HashMap::new()),
            session_ttl,
            tls,
        })
    }

    /// Whether clients must authenticate (at least one user exists).
    pub fn enabled(&self) -> bool {
        !self.books.read().unwrap().users.is_empty()
    }

    /// The client of a request: its bearer token or its session cookie. `Ok(None)`: it sent
    /// neither. A credential that is wrong, expired or revoked is a 401, whether or not the
    /// route needs one (a client should learn that its token is bad).
    pub fn authenticate(&self, headers: &HeaderMap) -> AppResult<Option<Principal>> {
        if let Some(v) = headers.get(header::AUTHORIZATION) {
            let v = v.to_str().unwrap_or_default().trim();
            let Some(token) = v
                .strip_prefix("Bearer ")
                .or_else(|| v.strip_prefix("bearer "))
            else {
                return Err(invalid_credentials(
                    "Authorization must be `Bearer <token>` (an API token)",
                ));
            };
            return self.token(token.trim()).map(Some);
        }
        match session_cookie(headers) {
            Some(secret) => self.session(secret).map(Some),
            None => Ok(None),
        }
    }

    fn token(&self, token: &str) -> AppResult<Principal> {
        let secret = sha256(token.as_bytes());
        let now = SystemTime::now();
        let mut books = self.books.write().unwrap();
        let Some(t) = books.tokens.iter_mut().find(|t| t.secret == secret) else {
            return Err(invalid_credentials("unknown API token"));
        };
        if t.revoked.is_some() {
            return Err(invalid_credentials(format!(
                "the API token {} was revoked",
                t.name
            )));
        }
        if t.expires.is_some_and(|e| e <= now) {
            return Err(invalid_credentials(format!(
                "the API token {} has expired",
                t.name
            )));
        }
        t.last_used = Some(now);
        if t.last_written
            .is_none_or(|w| w.elapsed() > Duration::from_secs(60))
        {
            t.last_written = Some(Instant::now());
            let (db, id, at) = (self.db.clone(), t.id, rfc3339(now));
            tokio::spawn(async move {
                if let Err(e) = store::auth::token_used(&db, id, &at).await {
                    tracing::warn!("cannot store the last use of token {id}: {e}");
                }
            });
        }
        Ok(Principal {
            kind: PrincipalKind::Token,
            name: t.name.clone(),
            role: t.role,
            secret,
        })
    }

    fn session(&self, cookie: &str) -> AppResult<Principal> {
        let secret = sha256(cookie.as_bytes());
        let books = self.books.read().unwrap();
        let Some(s) = books.sessions.get(&secret) else {
            return Err(unauthenticated(
                "the session is unknown or was ended: log in again",
            ));
        };
        if s.expires <= SystemTime::now() {
            return Err(unauthenticated("the session has expired: log in again"));
        }
        let Some(u) = books.users.get(&s.user_id) else {
            return Err(unauthenticated("the session's user was deleted"));
        };
        Ok(Principal {
            kind: PrincipalKind::User,
            name: u.name.clone(),
            role: u.role,
            secret,
        })
    }

    /// The principal as it stands now (its role may have changed), or why it is no longer
    /// valid (logged out, expired, revoked, deleted).
    pub fn recheck(&self, p: &Principal) -> AppResult<Principal> {
        let books = self.books.read().unwrap();
        match p.kind {
            PrincipalKind::User => {
                let s = books
                    .sessions
                    .get(&p.secret)
                    .filter(|s| s.expires > SystemTime::now())
                    .ok_or_else(|| unauthenticated("the session has ended: log in again"))?;
                let u = books
                    .users
                    .get(&s.user_id)
                    .ok_or_else(|| unauthenticated("the session's user was deleted"))?;
                Ok(Principal {
                    role: u.role,
                    ..p.clone()
                })
            }
            PrincipalKind::Token => {
                let t = books
                    .tokens
                    .iter()
                    .find(|t| t.secret == p.secret)
                    .filter(|t| {
                        t.revoked.is_none() && t.expires.is_none_or(|e| e > SystemTime::now())
                    })
                    .ok_or_else(|| invalid_credentials("the API token was revoked or expired"))?;
                Ok(Principal {
                    role: t.role,
                    ..p.clone()
                })
            }
        }
    }

    /// Checks the request's credentials against the role its route needs; `Ok(None)` when
    /// authentication is not enabled.
    pub fn authorize(&self, headers: &HeaderMap, need: Role) -> AppResult<Option<Principal>> {
        if !self.enabled() {
            return Ok(None);
        }
        match self.authenticate(headers)? {
            None => Err(unauthenticated(format!(
                "log in, or send `Authorization: Bearer <token>`; this needs the role {}",
                need.as_str()
            ))),
            Some(p) if p.role < need => Err(forbidden(&p, need)),
            Some(p) => Ok(Some(p)),
        }
    }

    /// Checks a name and password and opens a session.
    pub async fn login(&self, name: &str, password: &str) -> AppResult<NewSession> {
        let user_id = self.verify(name, password).await?;
        let cookie = b64(&random32());
        let secret = sha256(cookie.as_bytes());
        let now = SystemTime::now();
        let expires = now + self.session_ttl;
        store::auth::insert_session(&self.db, &secret, user_id, &rfc3339(now), &rfc3339(expires))
            .await
            .map_err(AppError::storage)?;
        let mut books = self.books.write().unwrap();
        books.sessions.retain(|_, s| s.expires > now);
        books.sessions.insert(secret, Session { user_id, expires });
        let u = &books.users[&user_id];
        Ok(NewSession {
            secret: cookie,
            expires,
            user: view(u),
        })
    }

    /// Checks a name and password: the user's id. Five failures for a name lock it for 30 s
    /// (429), whether or not it exists.
    pub async fn verify(&self, name: &str, password: &str) -> AppResult<i64> {
        {
            let mut f = self.failures.lock().unwrap();
            if let Some((n, at)) = f.get(name).copied() {
                if at.elapsed() >= LOCKOUT {
                    f.remove(name);
                } else if n >= MAX_FAILURES {
                    let left = (LOCKOUT - at.elapsed()).as_secs() + 1;
                    return Err(AppError::new(
                        StatusCode::TOO_MANY_REQUESTS,
                        "too_many_login_attempts",
                        "Too many login attempts",
                        format!("{MAX_FAILURES} failed logins for {name}: try again in {left} s"),
                    ));
                }
            }
        }
        let found = {
            let books = self.books.read().unwrap();
            books
                .users
                .values()
                .find(|u| u.name == name)
                .map(|u| (u.id, u.password_hash.clone()))
        };
        // An unknown name costs a hash too, so that timing does not tell which names exist.
        static DUMMY: std::sync::OnceLock<String> = std::sync::OnceLock::new();
        let hash = match &found {
            Some((_, h)) => h.clone(),
            None => DUMMY
                .get_or_init(|| hash_password("not a password of anyone").unwrap_or_default())
                .clone(),
        };
        let password = password.to_owned();
        let ok = tokio::task::spawn_blocking(move || verify_password(&password, &hash))
            .await
            .unwrap_or(false);
        let Some((user_id, _)) = found.filter(|_| ok) else {
            let mut f = self.failures.lock().unwrap();
            if f.len() > 10_000 {
                f.retain(|_, (_, at)| at.elapsed() < LOCKOUT);
            }
            let e = f.entry(name.to_owned()).or_insert((0, Instant::now()));
            e.0 += 1;
            e.1 = Instant::now();
            return Err(invalid_credentials("wrong user name or password"));
        };
        self.failures.lock().unwrap().remove(name);
        Ok(user_id)
    }

    /// Ends the session of a cookie (nothing when it is unknown).
    pub async fn logout(&self, cookie: &str) -> AppResult<()> {
        let secret = sha256(cookie.as_bytes());
        store::auth::delete_session(&self.db, &secret)
            .await
            .map_err(AppError::storage)?;
        self.books.write().unwrap().sessions.remove(&secret);
        Ok(())
    }

    pub fn session_expiry(&self, p: &Principal) -> Option<SystemTime> {
        let books = self.books.read().unwrap();
        (p.kind == PrincipalKind::User)
            .then(|| books.sessions.get(&p.secret).map(|s| s.expires))
            .flatten()
    }

    pub fn users(&self) -> Vec<UserView> {
        let books = self.books.read().unwrap();
        let mut v: Vec<_> = books.users.values().map(view).collect();
        v.sort_by(|a, b| a.name.cmp(&b.name));
        v
    }

    pub fn user(&self, name: &str) -> Option<UserView> {
        let books = self.books.read().unwrap();
        books.users.values().find(|u| u.name == name).map(view)
    }

    fn admins(books: &Books) -> usize {
        books
            .users
            .values()
            .filter(|u| u.role == Role::Admin)
            .count()
    }

    /// Creates a user; the first one must be an admin (it turns authentication on, and
    /// somebody must be able to manage users then).
    pub async fn add_user(
        &self,
        name: &str,
        role: Role,
        password: &str,
        audit: store::AuditEntry,
    ) -> AppResult<UserView> {
        check_name("name", name)?;
        check_password("password", password)?;
        let first = {
            let books = self.books.read().unwrap();
            if books.users.values().any(|u| u.name == name) {
                return Err(AppError::conflict(
                    "user_exists",
                    format!("a user {name} exists"),
                ));
            }
            if books.users.is_empty() && role != Role::Admin {
                return Err(AppError::field(
                    "role",
                    "the first user must be an admin (it turns authentication on)",
                ));
            }
            books.users.is_empty()
        };
        let hash = hash_off_thread(password).await?;
        let now = store::now_rfc3339();
        let mut tx = self.db.begin().await.map_err(AppError::storage)?;
        let id = store::auth::insert_user(&mut *tx, name, role.as_str(), &hash, &now)
            .await
            .map_err(|e| taken(e, "user_exists", format!("a user {name} exists")))?;
        // The first user turns authentication on: tokens made before it were made by nobody in
        // particular (open mode) and end now, in the same transaction (decision 118).
        let mut open_mode_tokens = Vec::new();
        if first {
            open_mode_tokens = store::auth::revoke_all_tokens(&mut *tx, &now)
                .await
                .map_err(AppError::storage)?;
            if !open_mode_tokens.is_empty() {
                let revoked = store::AuditEntry {
                    action: "token.revoke".into(),
                    target: None,
                    detail: serde_json::json!({
                        "reason": "authentication turned on: tokens made while it was off end",
                        "tokens": open_mode_tokens,
                    })
                    .to_string(),
                    outcome: Some("done".into()),
                    ..audit.clone()
                };
                store::audit(&mut *tx, &revoked)
                    .await
                    .map_err(AppError::storage)?;
            }
        }
        audit_and_commit(tx, &audit).await?;
        if !open_mode_tokens.is_empty() {
            tracing::warn!(
                "authentication is on (first user {name}): {} API token(s) made while it was off \
                 are revoked ({}); make new ones as an authenticated admin",
                open_mode_tokens.len(),
                open_mode_tokens.join(", ")
            );
            let mut books = self.books.write().unwrap();
            for t in books.tokens.iter_mut() {
                if open_mode_tokens.contains(&t.name) {
                    t.revoked.get_or_insert_with(|| now.clone());
                }
            }
        }
        let user = User {
            id,
            name: name.to_owned(),
            role,
            password_hash: hash,
            created_at: now,
        };
        let v = view(&user);
        self.books.write().unwrap().users.insert(id, user);
        Ok(v)
    }

    /// Changes a user's role and/or password. A password change ends the user's sessions
    /// (except `keep_session`, the one that changed its own password).
    pub async fn update_user(
        &self,
        name: &str,
        role: Option<Role>,
        password: Option<&str>,
        keep_session: Option<&Principal>,
        audit: store::AuditEntry,
    ) -> AppResult<UserView> {
        if let Some(p) = password {
            check_password("password", p)?;
        }
        let (id, old_role, old_hash) = {
            let books = self.books.read().unwrap();
            let u = books
                .users
                .values()
                .find(|u| u.name == name)
                .ok_or_else(|| AppError::not_found("user", name))?;
            if u.role == Role::Admin
                && role.is_some_and(|r| r != Role::Admin)
                && Self::admins(&books) == 1
            {
                return Err(AppError::conflict(
                    "last_admin",
                    format!("{name} is the last admin: make another user admin first"),
                ));
            }
            (u.id, u.role, u.password_hash.clone())
        };
        let hash = match password {
            Some(pw) => hash_off_thread(pw).await?,
            None => old_hash,
        };
        let role = role.unwrap_or(old_role);
        let mut tx = self.db.begin().await.map_err(AppError::storage)?;
        store::auth::update_user(&mut *tx, id, role.as_str(), &hash)
            .await
            .map_err(AppError::storage)?;
        if password.is_some() {
            store::auth::delete_sessions_of(&mut *tx, id)
                .await
                .map_err(AppError::storage)?;
            if let Some(keep) = keep_session.filter(|k| k.kind == PrincipalKind::User) {
                let expires = self.session_expiry(keep).unwrap_or_else(SystemTime::now);
                store::auth::insert_session(
                    &mut *tx,
                    &keep.secret,
                    id,
                    &store::now_rfc3339(),
                    &rfc3339(expires),
                )
                .await
                .map_err(AppError::storage)?;
            }
        }
        audit_and_commit(tx, &audit).await?;
        let mut books = self.books.write().unwrap();
        if password.is_some() {
            let keep = keep_session.map(|k| k.secret);
            books
                .sessions
                .retain(|s, v| v.user_id != id || Some(*s) == keep);
        }
        let u = books.users.get_mut(&id).expect("the user exists");
        u.role = role;
        u.password_hash = hash;
        Ok(view(u))
    }

    /// Deletes a user and its sessions; never the last admin.
    pub async fn delete_user(&self, name: &str, audit: store::AuditEntry) -> AppResult<()> {
        let id = {
            let books = self.books.read().unwrap();
            let u = books
                .users
                .values()
                .find(|u| u.name == name)
                .ok_or_else(|| AppError::not_found("user", name))?;
            if u.role == Role::Admin && Self::admins(&books) == 1 {
                return Err(AppError::conflict(
                    "last_admin",
                    format!("{name} is the last admin and cannot be deleted"),
                ));
            }
            u.id
        };
        let mut tx = self.db.begin().await.map_err(AppError::storage)?;
        store::auth::delete_sessions_of(&mut *tx, id)
            .await
            .map_err(AppError::storage)?;
        store::auth::delete_user(&mut *tx, id)
            .await
            .map_err(AppError::storage)?;
        audit_and_commit(tx, &audit).await?;
        let mut books = self.books.write().unwrap();
        books.users.remove(&id);
        books.sessions.retain(|_, s| s.user_id != id);
        Ok(())
    }

    pub fn tokens(&self) -> Vec<TokenView> {
        self.books
            .read()
            .unwrap()
            .tokens
            .iter()
            .map(token_view)
            .collect()
    }

    /// A new API token; its secret is in the answer only.
    pub async fn add_token(
        &self,
        name: &str,
        role: Role,
        expires_in_days: Option<u32>,
        created_by: &str,
        audit: store::AuditEntry,
    ) -> AppResult<NewToken> {
        check_name("name", name)?;
        if self
            .books
            .read()
            .unwrap()
            .tokens
            .iter()
            .any(|t| t.name == name)
        {
            return Err(AppError::conflict(
                "token_exists",
                format!("a token {name} exists (revoked tokens keep their names)"),
            ));
        }
        let token = format!("{TOKEN_PREFIX}{}", b64(&random32()));
        let secret = sha256(token.as_bytes());
        let now = SystemTime::now();
        let expires = expires_in_days.map(|d| now + Duration::from_secs(d as u64 * 86_400));
        let expires_at = expires.map(rfc3339);
        let mut tx = self.db.begin().await.map_err(AppError::storage)?;
        let id = store::auth::insert_token(
            &mut *tx,
            name,
            role.as_str(),
            &secret,
            created_by,
            &rfc3339(now),
            expires_at.as_deref(),
        )
        .await
        .map_err(|e| taken(e, "token_exists", format!("a token {name} exists")))?;
        audit_and_commit(tx, &audit).await?;
        let t = Token {
            id,
            name: name.to_owned(),
            role,
            secret,
            created_by: created_by.to_owned(),
            created_at: rfc3339(now),
            expires,
            last_used: None,
            last_written: None,
            revoked: None,
        };
        let view = token_view(&t);
        self.books.write().unwrap().tokens.push(t);
        Ok(NewToken { view, token })
    }

    /// Revokes a token (it stays listed, with its revocation time).
    pub async fn revoke_token(&self, id: i64, audit: store::AuditEntry) -> AppResult<TokenView> {
        if !self.books.read().unwrap().tokens.iter().any(|t| t.id == id) {
            return Err(AppError::not_found("token", &id.to_string()));
        }
        let at = store::now_rfc3339();
        let mut tx = self.db.begin().await.map_err(AppError::storage)?;
        store::auth::revoke_token(&mut *tx, id, &at)
            .await
            .map_err(AppError::storage)?;
        audit_and_commit(tx, &audit).await?;
        let mut books = self.books.write().unwrap();
        let t = books
            .tokens
            .iter_mut()
            .find(|t| t.id == id)
            .expect("the token exists");
        t.revoked.get_or_insert(at);
        Ok(token_view(t))
    }
}

fn view(u: &User) -> UserView {
    UserView {
        name: u.name.clone(),
        role: u.role,
        created_at: u.created_at.clone(),
    }
}

fn token_view(t: &Token) -> TokenView {
    TokenView {
        id: t.id,
        name: t.name.clone(),
        role: t.role,
        created_by: t.created_by.clone(),
        created_at: t.created_at.clone(),
        expires_at: t.expires.map(rfc3339),
        last_used_at: t.last_used.map(rfc3339),
        revoked_at: t.revoked.clone(),
    }
}

/// The session cookie's value, if the request has one.
pub fn session_cookie(headers: &HeaderMap) -> Option<&str> {
    headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .filter_map(|c| c.trim().split_once('='))
        .find(|(k, _)| *k == COOKIE)
        .map(|(_, v)| v)
}

/// `Set-Cookie` for a new session (HttpOnly, SameSite=Strict, Secure over TLS), or one that
/// ends it (`None`).
pub fn set_cookie(value: Option<(&str, Duration)>, tls: bool) -> String {
    let secure = if tls { "; Secure" } else { "" };
    match value {
        Some((v, ttl)) => format!(
            "{COOKIE}={v}; Path=/; HttpOnly; SameSite=Strict; Max-Age={}{secure}",
            ttl.as_secs()
        ),
        None => format!("{COOKIE}=; Path=/; HttpOnly; SameSite=Strict; Max-Age=0{secure}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_password_hash_verifies_only_its_password() {
        let h = hash_password("correct horse").unwrap();
        assert!(h.starts_with("$argon2id$"));
        assert!(verify_password("correct horse", &h));
        assert!(!verify_password("correct hors", &h));
        assert!(!verify_password("correct horse", "not a hash"));
    }

    #[test]
    fn the_session_cookie_is_found_among_others() {
        let mut h = HeaderMap::new();
        h.insert(
            header::COOKIE,
            "a=1; motiond_session=abc; b=2".parse().unwrap(),
        );
        assert_eq!(session_cookie(&h), Some("abc"));
        assert!(set_cookie(Some(("x", Duration::from_secs(60))), true).contains("; Secure"));
        assert!(set_cookie(None, false).contains("Max-Age=0"));
    }
}
