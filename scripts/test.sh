#!/usr/bin/env bash
# The project's test command: formatting, lints and every test, headless.
# Works on a fresh Debian 12 machine with a Rust toolchain: installs lavapipe (software
# Vulkan) with apt when no Vulkan driver for it is present.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
# shellcheck source=scripts/lib.sh
source scripts/lib.sh

section "Environment"
ensure_lavapipe
ensure_parallel
ensure_xvfb
ensure_rust_components
setup_gpu_env
# A clean clone gains nothing from incremental artefacts, and they cost gigabytes of disk.
if [[ -n "${CI:-}" ]]; then
    export CARGO_INCREMENTAL=0
fi
cargo --version
rustc --version

section "cargo fmt --check"
cargo fmt --all -- --check

section "cargo clippy (warnings are errors)"
cargo clippy --all-targets -- -D warnings

section "the tools crate compiles, lint-clean (benchmarks, probes, fuzz programs; not linked)"
cargo clippy -p gpu-render-tools --all-targets -- -D warnings

section "the library without the CLI's dependencies (cargo check --no-default-features)"
cargo check --lib --no-default-features

section "cargo test --all-targets"
cargo test --all-targets

section "cargo test --doc"
cargo test --doc

section "the library and program without the viewer (--no-default-features --features cli,vulkan)"
cargo clippy --all-targets --no-default-features --features cli,vulkan -- -D warnings

section "All checks passed"
