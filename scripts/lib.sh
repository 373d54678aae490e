# Shared helpers for the scripts in this directory; source it, do not run it.
#
#   ensure_lavapipe   install Mesa's software Vulkan driver (lavapipe) if it is missing
#   ensure_rust_components  rustfmt and clippy (rustup component add) if missing
#   setup_gpu_env     XDG_RUNTIME_DIR and WGPU_BACKEND defaults for headless wgpu
#   section TITLE     print a section header

section() {
    printf '\n==== %s ====\n' "$*"
}

# Runs a command as root: directly when root, through sudo when that exists.
as_root() {
    if [ "$(id -u)" -eq 0 ]; then
        "$@"
    elif command -v sudo >/dev/null 2>&1; then
        sudo "$@"
    else
        echo "warning: not root and no sudo; cannot run: $*" >&2
        return 1
    fi
}

have_lavapipe() {
    compgen -G '/usr/share/vulkan/icd.d/lvp_icd*.json' >/dev/null ||
        compgen -G '/etc/vulkan/icd.d/lvp_icd*.json' >/dev/null
}

# Installs mesa-vulkan-drivers (lavapipe) and the Vulkan loader with apt when the
# lavapipe ICD is missing, so wgpu finds at least a software adapter. Without apt (or
# without root) it warns and carries on: the GPU tests then skip or fall back.
ensure_lavapipe() {
    if have_lavapipe; then
        echo "lavapipe (software Vulkan) is installed"
        return 0
    fi
    if ! command -v apt-get >/dev/null 2>&1; then
        echo "warning: no lavapipe ICD and no apt-get; GPU tests may find no adapter" >&2
        return 0
    fi
    echo "installing lavapipe: mesa-vulkan-drivers libvulkan1"
    if as_root apt-get update -qq &&
        as_root env DEBIAN_FRONTEND=noninteractive \
            apt-get install -y -qq --no-install-recommends mesa-vulkan-drivers libvulkan1; then
        have_lavapipe || echo "warning: installed, but no lavapipe ICD found" >&2
    else
        echo "warning: could not install lavapipe; GPU tests may find no adapter" >&2
    fi
}

# rustfmt and clippy, which a minimal rustup profile leaves out.
ensure_rust_components() {
    if ! cargo fmt --version >/dev/null 2>&1 || ! cargo clippy --version >/dev/null 2>&1; then
        if command -v rustup >/dev/null 2>&1; then
            echo "installing rustfmt and clippy"
            rustup component add rustfmt clippy
        else
            echo "error: cargo fmt / cargo clippy are missing and rustup is not available" >&2
            return 1
        fi
    fi
}

# Headless wgpu wants a runtime directory and, by default here, Vulkan.
setup_gpu_env() {
    if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
        XDG_RUNTIME_DIR="${TMPDIR:-/tmp}/gpu-render-runtime-$(id -u)"
        mkdir -p "$XDG_RUNTIME_DIR"
        chmod 0700 "$XDG_RUNTIME_DIR"
        export XDG_RUNTIME_DIR
    fi
    export WGPU_BACKEND="${WGPU_BACKEND:-vulkan}"
    echo "XDG_RUNTIME_DIR=$XDG_RUNTIME_DIR WGPU_BACKEND=$WGPU_BACKEND"
}
