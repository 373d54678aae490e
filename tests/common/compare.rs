//! Image comparison (being written).
