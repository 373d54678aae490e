#!/usr/bin/env bash
# The real-GPU benchmark in one command (issue 30): prints one markdown table with the
# adapter (name, driver, the features the tracer cares about), the showcase at
# 1920x1080 (M rays/s), the million-triangle scene per traversal path (G rays/s), the
# Cornell box path-traced (M samples/s), a glTF model, and the kernel compile on a cold
# and on a warm driver cache, each row with its command. BENCHMARKS.md, "Real GPU",
# keeps the filled table.
#
#   scripts/gpu-bench.sh [--smoke] [--bin-dir DIR] [--out DIR] [--model FILE]
#                        [--gpu-render FILE] [--bench FILE] [--no-bench] [--runs N]
#
#   --smoke        tiny images, one run of each (40-80 s on 2 cores of lavapipe); CI
#                  runs it (tests/integration/gpu_bench.rs) so that the script cannot rot
#   --bin-dir DIR  where `gpu-render` and `bench` are. Default: .device/ if it holds
#                  them, else the release build (`cargo build --release -p gpu-render
#                  -p gpu-render-tools --bin gpu-render --bin bench` first, when cargo
#                  exists). Given binaries need no Rust toolchain and no network.
#   --gpu-render FILE, --bench FILE   the two binaries one by one (over --bin-dir)
#   --no-bench     leave out the rows that need `bench` (the million-triangle scene),
#                  saying so in the table (the CI smoke test builds only gpu-render)
#   --out DIR      also write the table to DIR/gpu-bench.md, every command's output to
#                  DIR/logs/ and the last image of each row to DIR/images/
#                  (default: $OUT when set)
#   --model FILE   the glTF (or OBJ) model of the model row. Default: the corpus's
#                  CesiumMilkTruck (../shared/realworld/draco/testdata/CesiumMilkTruck/
#                  glTF/CesiumMilkTruck.gltf, or a copy in .device/CesiumMilkTruck/),
#                  else the shipped scenes/models/vase.gltf
#   --runs N       timed runs per row (default 3; 1 with --smoke); rows give medians
#
# Every render runs with `--backend gpu` on the adapter wgpu prefers (as
# `gpu-render` without `--adapter` picks it); `WGPU_BACKEND` chooses the API (default
# vulkan). Each command may take GPU_BENCH_TIMEOUT seconds (default 180; 120 with
# --smoke). Exit status: 0 when every row measured; 1 when a row failed (the table is
# still printed, the row says FAILED and names its log); 2 for bad arguments or
# missing binaries; 3 when there is no GPU adapter at all.
#
# Sizes: the full run is meant to stay well inside 6 minutes on a data-centre GPU
# (about 12 processes, each loading its scene, opening the device and compiling its
# kernels, and about 1.7 G rays traced in all). It is not for lavapipe: there, with
# --runs 1, it took 5 minutes and the million-triangle row passed its time limit.
#
# Preparing a GPU machine that has a Vulkan driver but no Rust toolchain, no Vulkan
# loader and no network (glibc 2.35 or newer), on the development machine, from the
# repository root:
#
#   cargo build --release -p gpu-render -p gpu-render-tools --bin gpu-render --bin bench
#   mkdir -p .device && (grep -qx '/.device/' .git/info/exclude || echo /.device/ >> .git/info/exclude)
#   cp target/release/gpu-render target/release/bench .device/ && strip .device/*
#   mkdir -p .device/CesiumMilkTruck     # the corpus model, if the corpus is here
#   cp ../shared/realworld/draco/testdata/CesiumMilkTruck/glTF/* .device/CesiumMilkTruck/
#   # the Vulkan loader as a Debian package, unpacked there:
#   (grep -qx '/.gl/' .git/info/exclude || echo /.gl/ >> .git/info/exclude)
#   mkdir -p .gl /tmp/amd64/partial
#   o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
#   apt-get $o update && (cd .gl && apt-get $o download libvulkan1)
#
# and then on the GPU machine, from the copy of the repository (OUT: a folder whose
# files come back):
#
#   for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig
#   export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json   # NVIDIA
#   bash scripts/gpu-bench.sh --out "$OUT"
#
# Cold compile: the driver's shader cache is pointed at an empty folder
# (XDG_CACHE_HOME, MESA_SHADER_CACHE_DIR for Mesa, __GL_SHADER_DISK_CACHE_PATH for
# NVIDIA), and the warm row renders the same again with that folder filled. The
# showcase row uses that folder too (its kernels are those, whatever the image size),
# the other rows the machine's own cache; trace times never include the compile
# (uploads compile the kernels; the summary line reports that apart).
set -euo pipefail

usage() {
    sed -n '/^#   scripts\/gpu-bench.sh/,/^#   --runs/p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}

die() {
    echo "gpu-bench: $*" >&2
    exit 2
}

smoke=0
bin_dir=""
out="${OUT:-}"
model=""
gpu_render=""
bench=""
no_bench=0
runs=""
while (($#)); do
    case "$1" in
        --smoke) smoke=1 ;;
        --bin-dir) bin_dir="${2:?--bin-dir needs a folder}" && shift ;;
        --out) out="${2:?--out needs a folder}" && shift ;;
        --model) model="${2:?--model needs a file}" && shift ;;
        --gpu-render) gpu_render="${2:?--gpu-render needs a file}" && shift ;;
        --bench) bench="${2:?--bench needs a file}" && shift ;;
        --no-bench) no_bench=1 ;;
        --runs) runs="${2:?--runs needs a number}" && shift ;;
        -h | --help)
            usage
            exit 0
            ;;
        *) die "unknown argument $1 (see --help)" ;;
    esac
    shift
done
[[ -z "$runs" || "$runs" =~ ^[1-9][0-9]*$ ]] || die "--runs must be a positive number, not $runs"

# Paths given on the command line stay valid after the cd to the repository root.
absolute() {
    case "$1" in
        /*) printf '%s\n' "$1" ;;
        *) printf '%s/%s\n' "$PWD" "$1" ;;
    esac
}
[[ -z "$bin_dir" ]] || bin_dir="$(absolute "$bin_dir")"
[[ -z "$out" ]] || out="$(absolute "$out")"
[[ -z "$model" ]] || model="$(absolute "$model")"
[[ -z "$gpu_render" ]] || gpu_render="$(absolute "$gpu_render")"
[[ -z "$bench" ]] || bench="$(absolute "$bench")"

cd "$(dirname "${BASH_SOURCE[0]}")/.."
# shellcheck source=scripts/lib.sh
source scripts/lib.sh
setup_gpu_env >&2

# ---- the binaries ------------------------------------------------------------------
if [[ -z "$bin_dir" && (-z "$gpu_render" || (-z "$bench" && $no_bench == 0)) ]]; then
    if [[ -x .device/gpu-render ]]; then
        bin_dir="$PWD/.device"
    elif command -v cargo >/dev/null 2>&1; then
        echo "gpu-bench: building the release binaries (cargo build --release)" >&2
        packages=(-p gpu-render --bin gpu-render)
        ((no_bench)) || packages+=(-p gpu-render-tools --bin bench)
        cargo build --release "${packages[@]}" >&2
        bin_dir="$(absolute "${CARGO_TARGET_DIR:-target}")/release"
    else
        die "no binaries: no .device/gpu-render and no cargo to build them; pass --bin-dir DIR (see the header of this script)"
    fi
fi
gpu_render="${gpu_render:-$bin_dir/gpu-render}"
[[ -x "$gpu_render" ]] || die "gpu-render not found or not executable: $gpu_render"
if ((no_bench)); then
    bench=""
    bench_missing="left out (--no-bench)"
else
    bench="${bench:-$bin_dir/bench}"
    bench_missing=""
    if [[ ! -x "$bench" ]]; then
        bench_missing="no bench binary at $bench"
        # The full benchmark is not complete without it; the smoke run says so and goes on.
        ((smoke)) || echo "gpu-bench: $bench_missing; the million-triangle row fails" >&2
    fi
fi
version="$("$gpu_render" --version 2>&1)" ||
    die "$gpu_render does not run here (glibc 2.35 or newer is needed): $version"

if [[ -z "$model" ]]; then
    for candidate in ../shared/realworld/draco/testdata/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf \
        .device/CesiumMilkTruck/CesiumMilkTruck.gltf scenes/models/vase.gltf; do
        if [[ -f "$candidate" ]]; then
            model="$candidate"
            break
        fi
    done
fi
[[ -f "$model" ]] || die "model not found: $model"

# ---- sizes ---------------------------------------------------------------------------
if ((smoke)); then
    mode="smoke (tiny sizes)"
    runs="${runs:-1}"
    timeout_s="${GPU_BENCH_TIMEOUT:-120}"
    showcase_size=(--width 64 --height 36 --spp 4)
    million_size=(--width 64 --height 36 --spp 1)
    cornell_size=(--width 32 --height 32 --spp 4)
    model_size=(--width 64 --height 36 --spp 1)
    compile_size=(--width 32 --height 18 --spp 1)
else
    mode="full"
    runs="${runs:-3}"
    timeout_s="${GPU_BENCH_TIMEOUT:-180}"
    showcase_size=(--width 1920 --height 1080 --spp 4)
    # 16 samples per pixel: at a billion rays a second one would take 5 ms.
    million_size=(--width 1920 --height 1080 --spp 16)
    cornell_size=(--width 1024 --height 1024 --spp 64)
    model_size=(--width 1920 --height 1080 --spp 16)
    compile_size=(--width 64 --height 36 --spp 1)
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/gpu-bench.XXXXXX")"
trap 'rm -rf "$work"' EXIT
if [[ -n "$out" ]]; then
    mkdir -p "$out/logs" "$out/images"
    logs="$out/logs"
    images="$out/images"
else
    mkdir -p "$work/logs" "$work/images"
    logs="$work/logs"
    images="$work/images"
fi

failures=0
rows=()

# Adds a table row, its cells the arguments.
row() {
    local cell line="|"
    for cell in "$@"; do
        line+=" $cell |"
    done
    rows+=("$line")
}

# `gpu-render` and `bench` as the table's commands name them.
shown() {
    local word text=""
    for word in "$@"; do
        case "$word" in
            "$gpu_render") word=gpu-render ;;
            "$bench") word=bench ;;
            "$work"/*) word="${word##*/}" ;;
            "$PWD"/*) word="${word#"$PWD"/}" ;;
        esac
        text+="${text:+ }$word"
    done
    printf '%s' "$text"
}

# "64x36, 4 spp" for `--width 64 --height 36 --spp 4`, the scene's spp by default.
size_text() {
    local width="" height="" spp="the scene's"
    while (($#)); do
        case "$1" in
            --width) width="$2" ;;
            --height) height="$2" ;;
            --spp) spp="$2" ;;
        esac
        shift 2
    done
    printf '%s%s spp' "${width:+${width}x$height, }" "$spp"
}

# Runs a command with the time limit, its output (both streams) in the log LOG.
# Returns its status; prints the end of the log on failure.
run_logged() {
    local log="$1"
    shift
    local status=0
    if command -v timeout >/dev/null 2>&1; then
        timeout "$timeout_s" "$@" >"$log" 2>&1 || status=$?
    else
        "$@" >"$log" 2>&1 || status=$?
    fi
    if ((status != 0)); then
        local why="status $status"
        ((status != 124)) || why="over the time limit of $timeout_s s"
        {
            echo "gpu-bench: failed ($why): $(shown "$@")"
            tail -n 15 "$log" | sed 's/^/    /'
        } >&2
    fi
    return "$status"
}

# The summary line of a gpu-render log, without any progress output before it.
summary_line() {
    tr '\r' '\n' <"$1" | grep -E '^rendered .* on GPU \(' | tail -n 1
}

# Field NAME of the summary line $1: trace, source, rate (M rays/s), rays, compile,
# wall, adapter.
summary_field() {
    local pattern
    case "$2" in
        trace) pattern='.*, trace ([0-9.]+) s \(.*' ;;
        source) pattern='.*, trace [0-9.]+ s \(([^)]*)\).*' ;;
        rate) pattern='.*, ([0-9.]+) Mrays/s.*' ;;
        rays) pattern='.*\): ([0-9.]+( [MG])?) rays,.*' ;;
        compile) pattern='.*\(kernel compile ([0-9.]+) s\).*' ;;
        wall) pattern='.* in ([0-9.]+) s \(kernel compile.*' ;;
        adapter) pattern='.* on GPU \((.*)\) in [0-9.]+ s \(kernel compile.*' ;;
    esac
    sed -E -n "s#^${pattern}\$#\\1#p" <<<"$1"
}

# "55.42 M" -> 55420000.
count() {
    awk -v c="$1" 'BEGIN { n = c + 0; if (c ~ / M$/) n *= 1e6; if (c ~ / G$/) n *= 1e9; printf "%.0f\n", n }'
}

# The median of the arguments (the upper one of an even count, as bench takes it).
median() {
    printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int(NR / 2) + 1] }'
}

# Renders with gpu-render RUNS times, under `render_env` (a command prefix, or empty); sets `measured` to the summary lines, one per
# run, or returns non-zero (and counts a failure) when a run fails or prints none.
# Arguments: NAME, then gpu-render's arguments (the output path is added).
measured=()
render_env=()
render_runs() {
    local name="$1"
    shift
    local run line
    measured=()
    for ((run = 1; run <= runs; run++)); do
        run_logged "$logs/$name-$run.txt" "${render_env[@]}" "$gpu_render" "$@" --backend gpu \
            -o "$images/$name.png" || return 1
        line="$(summary_line "$logs/$name-$run.txt")"
        if [[ -z "$line" || -z "$(summary_field "$line" rate)" ]]; then
            echo "gpu-bench: no summary line in $logs/$name-$run.txt" >&2
            return 1
        fi
        measured+=("$line")
    done
}

# Prints "median-rate median-trace source rays first-compile" of `measured`.
render_figures() {
    local line rates=() traces=()
    for line in "${measured[@]}"; do
        rates+=("$(summary_field "$line" rate)")
        traces+=("$(summary_field "$line" trace)")
    done
    printf '%s|%s|%s|%s|%s\n' "$(median "${rates[@]}")" "$(median "${traces[@]}")" \
        "$(summary_field "${measured[0]}" source)" "$(summary_field "${measured[0]}" rays)" \
        "$(summary_field "${measured[0]}" compile)"
}

# A row whose command failed, counted: LABEL SETTING LOG COMMAND.
failed_row() {
    failures=$((failures + 1))
    row "$1" "$2" "**FAILED**" "see $3" "\`$4\`"
}

runs_text() {
    if ((runs == 1)); then echo "1 run"; else echo "median of $runs runs"; fi
}

# ---- the adapter ---------------------------------------------------------------------
if ! run_logged "$logs/adapters.txt" "$gpu_render" --adapter list; then
    echo "gpu-bench: \`gpu-render --adapter list\` failed (log above)" >&2
    exit 1
fi
if ! grep -qE '^[0-9]+: ' "$logs/adapters.txt"; then
    cat >&2 <<EOF
gpu-bench: no GPU adapter found (\`gpu-render --adapter list\`: $(tr '\n' ' ' <"$logs/adapters.txt"))
  Is a Vulkan driver installed and found? On a machine prepared as this script's header
  says: the loader from .gl/ unpacked (dpkg -x) and ldconfig run, and VK_DRIVER_FILES
  naming the driver's ICD file (NVIDIA: /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json).
  For lavapipe: scripts/lib.sh's ensure_lavapipe. WGPU_BACKEND=${WGPU_BACKEND:-} chooses the API.
EOF
    exit 3
fi

started=$SECONDS

# ---- kernel compile, cold then warm (first: the showcase's kernels are then cold) ------
cache="$work/driver-cache"
mkdir -p "$cache/mesa" "$cache/nvidia"
compile_env=(env XDG_CACHE_HOME="$cache" MESA_SHADER_CACHE_DIR="$cache/mesa"
    MESA_SHADER_CACHE_DISABLE=false __GL_SHADER_DISK_CACHE=1
    __GL_SHADER_DISK_CACHE_PATH="$cache/nvidia" __GL_SHADER_DISK_CACHE_SKIP_CLEANUP=1)
compile_args=(scenes/showcase.toml "${compile_size[@]}" --backend gpu -o "$work/compile.png")
compile_command="$(shown "${compile_env[@]}" "$gpu_render" "${compile_args[@]}")"
compile_command="${compile_command//$cache/EMPTY-DIR}"
adapter_used=""
for temperature in cold warm; do
    name="compile-$temperature"
    if [[ $temperature == cold ]]; then
        label="kernel compile, cold (an empty driver shader cache)"
    else
        label="kernel compile, warm (the same again, the cache filled)"
    fi
    setting="the showcase's kernels, $(size_text "${compile_size[@]}")"
    if run_logged "$logs/$name.txt" "${compile_env[@]}" "$gpu_render" "${compile_args[@]}" &&
        line="$(summary_line "$logs/$name.txt")" && [[ -n "$(summary_field "$line" compile)" ]]; then
        adapter_used="$(summary_field "$line" adapter)"
        row "$label" "$setting" "**$(summary_field "$line" compile) s**" \
            "the whole render call $(summary_field "$line" wall) s; 1 run" "\`$compile_command\`"
    else
        failed_row "$label" "$setting" "logs/$name.txt" "$compile_command"
    fi
done

compile_rows=("${rows[@]}")
rows=()

# ---- the adapter row -----------------------------------------------------------------
adapter_line=""
if [[ -n "$adapter_used" ]]; then
    adapter_line="$(awk -v name="$adapter_used" 'index($0, ": " name " (") { print; exit }' "$logs/adapters.txt")"
fi
# Without a render that named it: the first listed (one adapter is the usual case).
[[ -n "$adapter_line" ]] || adapter_line="$(grep -m 1 -E '^[0-9]+: ' "$logs/adapters.txt")"
# `N: NAME (BACKEND, TYPE, driver DRIVER; FEATURES)`; NAME and DRIVER may hold brackets.
backends='vulkan|metal|dx12|gl|webgpu|noop'
adapter_name="$(sed -E "s/^[0-9]+: (.*) \(($backends), .*\)\$/\\1/" <<<"$adapter_line")"
adapter_detail="$(sed -E "s/^[0-9]+: .* \((($backends), .*)\)\$/\\1/" <<<"$adapter_line")"
ray_query="$(sed -E -n 's/.*EXPERIMENTAL_RAY_QUERY (yes|no).*/\1/p' <<<"$adapter_line")"
adapter_row="| adapter | $adapter_name | ${adapter_detail%;*} | ${adapter_detail##*; } | \`gpu-render --adapter list\` |"

# ---- the showcase --------------------------------------------------------------------
args=(scenes/showcase.toml "${showcase_size[@]}")
command="$(shown "$gpu_render" "${args[@]}") --backend gpu -o showcase.png"
setting="$(size_text "${showcase_size[@]}"), depth 8"
# In the compile rows' cache, where its kernels already are.
render_env=("${compile_env[@]}")
showcase_ok=0
render_runs showcase "${args[@]}" && showcase_ok=1
render_env=()
if ((showcase_ok)); then
    IFS='|' read -r rate trace source rays compile <<<"$(render_figures)"
    row "showcase" "$setting" "**$rate M rays/s**" \
        "trace $trace s ($source), $rays rays, $(runs_text); kernel compile $compile s (first run)" \
        "\`$command\`"
else
    failed_row "showcase" "$setting" "logs/showcase-*.txt" "$command"
fi

# ---- the million-triangle scene, per traversal path -----------------------------------
# One row per path: LABEL, the --gpu-traversal value, the log's name.
million_row() {
    local label="$1" traversal="$2" log="$logs/$3.txt"
    local args=(generated:million "${million_size[@]}" --runs "$runs" --gpu-only --gpu-traversal "$traversal")
    local command wall_line rays stamp_line trace mrays source build grays
    command="$(shown "$bench" "${args[@]}")"
    [[ -n "$bench" ]] || command="bench ${args[*]}"
    if [[ -n "$bench_missing" ]]; then
        if ((smoke)) || ((no_bench)); then
            row "$label" "$million_setting" "skipped" "$bench_missing" "\`$command\`"
        else
            failures=$((failures + 1))
            row "$label" "$million_setting" "**FAILED**" "$bench_missing" "\`$command\`"
        fi
    elif run_logged "$log" "$bench" "${args[@]}" &&
        wall_line="$(grep -E '^GPU: trace [0-9.]+ s \(wall clock\)' "$log")"; then
        rays="$(sed -E -n 's/.*; ([0-9]+) rays;.*/\1/p' <<<"$wall_line")"
        stamp_line="$(grep -E '^GPU: trace passes [0-9.]+ s \(GPU timestamps\)' "$log" || true)"
        # The rate as bench prints it: from the unrounded time (a real GPU's is milliseconds).
        if [[ -n "$stamp_line" ]]; then
            trace="$(sed -E -n 's/^GPU: trace passes ([0-9.]+) s.*/\1/p' <<<"$stamp_line")"
            mrays="$(sed -E -n 's/.*; ([0-9.]+) Mrays\/s.*/\1/p' <<<"$stamp_line")"
            source="GPU timestamps"
        else
            trace="$(sed -E -n 's/^GPU: trace ([0-9.]+) s.*/\1/p' <<<"$wall_line")"
            mrays="$(sed -E -n 's/.*; ([0-9.]+) Mrays\/s.*/\1/p' <<<"$wall_line")"
            source="wall clock"
        fi
        build="$(sed -E -n 's/.*BVH built in ([0-9.]+) ms.*/\1/p' "$log")"
        grays="$(awk -v m="$mrays" 'BEGIN { printf "%.3g", m / 1e3 }')"
        row "$label" "$million_setting" "**$grays G rays/s** ($mrays M rays/s)" \
            "trace $trace s ($source), $rays rays, $(runs_text) after a warm-up; BVH built in $build ms" \
            "\`$command\`"
    else
        failed_row "$label" "$million_setting" "logs/$3.txt" "$command"
    fi
}
million_setting="1,002,528 triangles + 5 spheres, $(size_text "${million_size[@]}"), depth 4: camera and shadow rays (2 lights), and the mirror and glass spheres' few secondary rays"
million_row "million-triangle, software BVH" software million
if [[ "$ray_query" == yes ]]; then
    million_row "million-triangle, hardware ray queries" hardware million-hardware
else
    row "million-triangle, hardware ray queries" "the same" "n/a" \
        "the adapter lacks EXPERIMENTAL_RAY_QUERY (the software row is what it runs)" ""
fi

# ---- the Cornell box, path traced -------------------------------------------------------
args=(scenes/cornell-box.toml "${cornell_size[@]}")
command="$(shown "$gpu_render" "${args[@]}") --backend gpu -o cornell.png"
pixels="$(shown "${cornell_size[@]}" | awk '{ print $2 * $4 * $6 }')"
setting="$(size_text "${cornell_size[@]}"), depth 8, path integrator"
if render_runs cornell "${args[@]}"; then
    IFS='|' read -r rate trace source rays compile <<<"$(render_figures)"
    samples="$(awk -v p="$pixels" -v r="$rate" -v n="$(count "$rays")" 'BEGIN { printf "%.1f", p * r / n }')"
    row "Cornell box, path traced" "$setting" "**$samples M samples/s**" \
        "$rate M rays/s; trace $trace s ($source), $rays rays for $pixels samples, $(runs_text); kernel compile $compile s (first run)" \
        "\`$command\`"
else
    failed_row "Cornell box, path traced" "$setting" "logs/cornell-*.txt" "$command"
fi

# ---- a glTF model ----------------------------------------------------------------------
args=("$model" "${model_size[@]}")
command="$(shown "$gpu_render" "${args[@]}") --backend gpu -o model.png"
setting="$(size_text "${model_size[@]}"), depth 5, Whitted, the default camera and lights"
label="model ${model##*/}"
if render_runs model "${args[@]}"; then
    IFS='|' read -r rate trace source rays compile <<<"$(render_figures)"
    row "$label" "$setting" "**$rate M rays/s**" \
        "trace $trace s ($source), $rays rays, $(runs_text); kernel compile $compile s (first run)" \
        "\`$command\`"
else
    failed_row "$label" "$setting" "logs/model-*.txt" "$command"
fi

# ---- the table -----------------------------------------------------------------------
commit="$(git rev-parse --short HEAD 2>/dev/null || echo "unknown (no git here)")"
{
    echo "gpu-bench, $mode, $(date -u +%Y-%m-%d), commit $commit, $version, binaries from $(dirname "$gpu_render"), $((SECONDS - started + 0)) s"
    echo
    echo "| benchmark | setting | figure | detail | command |"
    echo "|---|---|---|---|---|"
    echo "$adapter_row"
    # The workloads, then the compile rows (measured first, while the cache is empty).
    printf '%s\n' "${rows[@]}" "${compile_rows[@]}"
} >"$work/gpu-bench.md"
cat "$work/gpu-bench.md"
[[ -z "$out" ]] || cp "$work/gpu-bench.md" "$out/gpu-bench.md"
if ((failures)); then
    # Without --out the logs are in the work folder: keep it for them.
    [[ -n "$out" ]] || trap - EXIT
    echo "gpu-bench: $failures row(s) failed; their logs: $logs" >&2
    exit 1
fi
