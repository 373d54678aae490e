//! GPU test helpers (being written).
