# Shared helpers for the scripts in this directory; source it, do not run it.
#
#   ensure_lavapipe   install Mesa's software Vulkan driver (lavapipe) if it is missing
#                     (on Debian 12 from bookworm-backports: Mesa 25)
#   ensure_rust_components  rustfmt and clippy (rustup component add) if missing
#   ensure_parallel   install GNU parallel (the recipe test runs it) if it is missing
#   ensure_xvfb       install Xvfb (the viewer's window tests start it) if it is missing
#   ensure_oidn       Intel Open Image Denoise (the pyoidn wheel's copy) in .oidn/, and
#                     OIDN_DIR naming it, for the `oidn` feature (x86-64 Linux)
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

# The Debian release this machine runs ("bookworm" for Debian 12), or nothing.
debian_codename() {
    # shellcheck disable=SC1091
    [ -r /etc/os-release ] && (. /etc/os-release && echo "${VERSION_CODENAME:-}")
}

# The Mesa version of the installed lavapipe ("25.0.7-2~bpo12+1"), or nothing.
installed_mesa_version() {
    dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null
}

# Installs mesa-vulkan-drivers (lavapipe) and the Vulkan loader with apt when the
# lavapipe ICD is missing, so wgpu finds at least a software adapter. On Debian 12 it
# takes Mesa from bookworm-backports (25.0.x) rather than bookworm's 22.3.6: the GPU
# tracer runs about 3x faster on it and its loops have no 65,535-iteration limit
# (BENCHMARKS.md, "lavapipe versions"). GPU_RENDER_LAVAPIPE=stock keeps the release's
# own Mesa. Without apt (or without root) it warns and carries on: the GPU tests then
# skip or fall back.
ensure_lavapipe() {
    if have_lavapipe; then
        echo "lavapipe (software Vulkan) is installed: Mesa $(installed_mesa_version)"
        case "$(installed_mesa_version)" in
            2[0-4].*)
                echo "note: Mesa 25 from bookworm-backports runs the GPU tracer about 3x faster" \
                    "(see BENCHMARKS.md); this Mesa works, with a smaller iteration budget" >&2
                ;;
        esac
        return 0
    fi
    if ! command -v apt-get >/dev/null 2>&1; then
        echo "warning: no lavapipe ICD and no apt-get; GPU tests may find no adapter" >&2
        return 0
    fi
    local target=()
    if [ "$(debian_codename)" = bookworm ] && [ "${GPU_RENDER_LAVAPIPE:-backports}" != stock ]; then
        local list=/etc/apt/sources.list.d/gpu-render-bookworm-backports.list
        if [ ! -e "$list" ]; then
            echo "deb http://deb.debian.org/debian bookworm-backports main" |
                as_root tee "$list" >/dev/null || true
        fi
        target=(-t bookworm-backports)
    fi
    echo "installing lavapipe: mesa-vulkan-drivers libvulkan1 ${target[*]}"
    if as_root apt-get update -qq &&
        as_root env DEBIAN_FRONTEND=noninteractive \
            apt-get install -y -qq --no-install-recommends "${target[@]}" \
            mesa-vulkan-drivers libvulkan1; then
        have_lavapipe || echo "warning: installed, but no lavapipe ICD found" >&2
        echo "lavapipe installed: Mesa $(installed_mesa_version)"
    elif [ "${#target[@]}" -gt 0 ] &&
        as_root env DEBIAN_FRONTEND=noninteractive \
            apt-get install -y -qq --no-install-recommends mesa-vulkan-drivers libvulkan1; then
        echo "warning: bookworm-backports failed; installed the release's Mesa $(installed_mesa_version)" >&2
    else
        echo "warning: could not install lavapipe; GPU tests may find no adapter" >&2
    fi
}

# GNU parallel, whose recipe (distributed/parallel/render.sh) tests/integration/recipes.rs runs.
# Without apt (or root) it warns and carries on: that test then skips, except in CI.
ensure_parallel() {
    if command -v parallel >/dev/null 2>&1; then
        return 0
    fi
    echo "installing GNU parallel"
    if ! { command -v apt-get >/dev/null 2>&1 &&
        as_root apt-get update -qq &&
        as_root env DEBIAN_FRONTEND=noninteractive \
            apt-get install -y -qq --no-install-recommends parallel; }; then
        echo "warning: could not install GNU parallel; its recipe test will skip" >&2
    fi
}

# Xvfb, the virtual X server that tests/integration/viewer.rs starts to open the viewer's window
# (and wgpu's surface on it) without a display, and the X11 client libraries winit
# loads at run time (Xlib with its XCB bridge, xkbcommon's X11 keymaps, the cursor,
# RandR and input extensions). Without apt (or root) it warns and carries on: those
# tests then skip, except in CI, where they fail.
VIEWER_X11_PACKAGES=(xvfb libx11-6 libx11-xcb1 libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6)
ensure_xvfb() {
    local installed
    installed=$(dpkg-query -W -f='${Status}\n' "${VIEWER_X11_PACKAGES[@]}" 2>/dev/null |
        grep -c 'install ok installed' || true)
    if command -v Xvfb >/dev/null 2>&1 && [ "${installed:-0}" -eq "${#VIEWER_X11_PACKAGES[@]}" ]; then
        return 0
    fi
    echo "installing Xvfb and the X11 libraries of the viewer: ${VIEWER_X11_PACKAGES[*]}"
    if ! { command -v apt-get >/dev/null 2>&1 &&
        as_root apt-get update -qq &&
        as_root env DEBIAN_FRONTEND=noninteractive \
            apt-get install -y -qq --no-install-recommends "${VIEWER_X11_PACKAGES[@]}"; }; then
        echo "warning: could not install Xvfb; the viewer's window tests will skip" >&2
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

# Intel Open Image Denoise for the `oidn` feature (`--denoise oidn`), which opens the
# library at run time from $OIDN_DIR/lib. OIDN's own release packages come from GitHub;
# the pyoidn wheel on PyPI bundles the same library (2.5.1, with its TBB), so pip
# installs it, pinned by hash, into the project's git-ignored .oidn/ and OIDN_DIR is
# exported as its pyoidn/oidn folder. The wheel's GPU device modules (CUDA, HIP, SYCL and
# their runtimes, 100 MB of 170) and programs are removed: the binding uses the CPU
# device. LD_LIBRARY_PATH is left alone: the library is opened by path and finds its
# own dependencies through its RPATH ($ORIGIN). Returns 1 (with a message) where pip or
# the wheel is not available; the caller decides whether that is fatal.
OIDN_WHEEL="pyoidn==2.5.1.0"
OIDN_WHEEL_SHA256=32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e
ensure_oidn() {
    local root dir
    root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
    dir="$root/.oidn/pyoidn/oidn"
    if [ ! -e "$dir/lib/libOpenImageDenoise.so.2" ]; then
        if [ "$(uname -s)-$(uname -m)" != "Linux-x86_64" ]; then
            echo "error: ensure_oidn installs the pyoidn wheel, built for x86-64 Linux only; install Open Image Denoise 2 and set OIDN_DIR" >&2
            return 1
        fi
        if ! python3 -m pip --version >/dev/null 2>&1; then
            echo "installing pip (python3-pip), to fetch the pyoidn wheel"
            if ! { command -v apt-get >/dev/null 2>&1 &&
                as_root apt-get update -qq &&
                as_root env DEBIAN_FRONTEND=noninteractive \
                    apt-get install -y -qq --no-install-recommends python3-pip; }; then
                echo "error: ensure_oidn needs pip (python3 -m pip) to install the pyoidn wheel" >&2
                return 1
            fi
        fi
        echo "installing Intel Open Image Denoise ($OIDN_WHEEL) into $root/.oidn"
        rm -rf "$root/.oidn"
        local requirements
        requirements="$(mktemp)"
        printf '%s --hash=sha256:%s\n' "$OIDN_WHEEL" "$OIDN_WHEEL_SHA256" >"$requirements"
        if ! python3 -m pip install --quiet --disable-pip-version-check --root-user-action=ignore --no-deps \
            --only-binary=:all: --require-hashes --target "$root/.oidn" -r "$requirements"; then
            rm -f "$requirements"
            echo "error: could not install $OIDN_WHEEL with pip" >&2
            return 1
        fi
        rm -f "$requirements"
        rm -rf "$dir/bin" "$dir/lib/cmake" "$dir"/lib/libOpenImageDenoise_device_{cuda,hip,sycl}* \
            "$dir"/lib/libsycl* "$dir"/lib/libur_* "$dir"/lib/libumf*
    fi
    export OIDN_DIR="$dir"
    echo "OIDN_DIR=$OIDN_DIR"
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
