//! The service layer: the rules of each request and its transactions, for every transport.
//! Handlers (`crate::api`) parse and answer; these functions decide and act, on the state of
//! `crate::app`, the SQL of `crate::store` and the cycle thread; errors are `AppError`.

pub mod axes;
pub mod cams;
pub mod commands;
pub mod control;
pub mod idempotency;
pub mod reads;
pub mod scope;
pub mod simulation;
