//! The remembered `Idempotency-Key`s of motion commands and their answers. What a key does to
//! a request is the service's (`crate::service::idempotency`).

use std::collections::{HashMap, VecDeque};
use std::sync::Mutex;

use motion::ErrorId;
use tokio::time::Instant;

use crate::model::CommandResource;

/// What a key's first request got.
#[derive(Clone, Debug)]
pub(crate) enum Answer {
    /// Boxed: a command resource is large, a refusal small (both kept per key).
    Accepted(Box<CommandResource>),
    /// Refused by the axis, with what was in the way then.
    Rejected(ErrorId, Option<String>),
}

#[derive(Debug)]
pub(crate) struct Remembered {
    /// Block, axis and body as sent: the same key with another request is refused.
    pub(crate) fingerprint: String,
    pub(crate) at: Instant,
    /// `None` while the first request is still being answered.
    pub(crate) answer: Option<Answer>,
}

/// The keys by name, and their names oldest first (to forget the oldest).
pub(crate) type Memory = (HashMap<String, Remembered>, VecDeque<(Instant, String)>);

/// The keys of recent commands.
#[derive(Default)]
pub struct Keys {
    pub(crate) inner: Mutex<Memory>,
}
