//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod compare;
pub mod geometry;
pub mod gpu;
pub mod process;
pub mod reference;
pub mod scenes;
pub mod twins;
