//! Property tests across segment kinds.
