//! The wgpu backend (being written).

pub mod layout;
