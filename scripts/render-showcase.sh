#!/usr/bin/env bash
# Renders scenes/showcase.toml to showcase.png (extra arguments go to gpu-render,
# e.g. `--backend cpu` or `--spp 64`).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
# shellcheck source=scripts/lib.sh
source scripts/lib.sh

section "Environment"
ensure_lavapipe
setup_gpu_env

section "Rendering scenes/showcase.toml"
cargo run --release -- scenes/showcase.toml -o showcase.png "$@"
