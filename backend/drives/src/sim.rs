//! Simulated servo drive (being written).
