#!/usr/bin/env bash
# GNU parallel on one machine of several cores or GPUs:
#
#   distributed/parallel/render.sh tiles SCENE N OUTPUT      # N tiles, then the merge
#   distributed/parallel/render.sh frames SCENE FIRST LAST   # frames FIRST..LAST
#
# Environment:
#   JOBS             processes at once (default: the number of ADAPTERS, else 1)
#   ADAPTERS         GPU adapter indices from `gpu-render --adapter list`, e.g. "0 1":
#                    the job in parallel's slot k runs on the k-th (--adapter INDEX),
#                    so two jobs never share a GPU
#   BACKEND          auto, gpu or cpu (default: auto; gpu when ADAPTERS is set)
#   WORK_DIR         where tiles go (default: tiles); frames go to FRAME_NAME
#   FRAME_NAME       default: frames/frame-{frame}.png
#   GPU_RENDER       the program (default: gpu-render on PATH)
#   GPU_RENDER_ARGS  more options, e.g. "--spp 64"
set -euo pipefail

usage() {
    sed -n '2,5p' "${BASH_SOURCE[0]}" >&2
    exit 2
}
[ "$#" -eq 4 ] || usage
mode=$1
export SCENE=$2
command -v parallel >/dev/null || {
    echo "GNU parallel is not installed (Debian: apt-get install parallel)" >&2
    exit 1
}
read -ra adapters <<<"${ADAPTERS:-}"
export ADAPTERS="${adapters[*]}"
export BACKEND="${BACKEND:-$([ "${#adapters[@]}" -gt 0 ] && echo gpu || echo auto)}"
export GPU_RENDER="${GPU_RENDER:-gpu-render}" GPU_RENDER_ARGS="${GPU_RENDER_ARGS:-}"
jobs="${JOBS:-$([ "${#adapters[@]}" -gt 0 ] && echo "${#adapters[@]}" || echo 1)}"

# One piece: $1 is the index (--tile $1/N or --frame $1), $2 parallel's job slot.
render_one() {
    local index=$1 slot=$2 device=() list extra
    read -ra list <<<"$ADAPTERS"
    if [ "${#list[@]}" -gt 0 ]; then
        device=(--adapter "${list[$(((slot - 1) % ${#list[@]}))]}")
    fi
    read -ra extra <<<"$GPU_RENDER_ARGS"
    if [ "$MODE" = tiles ]; then
        "$GPU_RENDER" "$SCENE" --tile "$index/$TILES" --backend "$BACKEND" "${device[@]}" \
            "${extra[@]}" -q -o "$WORK_DIR/tile-{tile}.exr"
    else
        "$GPU_RENDER" "$SCENE" --frame "$index" --backend "$BACKEND" "${device[@]}" \
            "${extra[@]}" -q -o "$FRAME_NAME"
    fi
}
export -f render_one
export PARALLEL_SHELL=bash MODE="$mode"

case "$mode" in
    tiles)
        export TILES=$3 WORK_DIR="${WORK_DIR:-tiles}"
        output=$4
        mkdir -p "$WORK_DIR"
        parallel --jobs "$jobs" --halt soon,fail=1 render_one {} {%} ::: $(seq 0 $((TILES - 1)))
        # The names of {tile}: the index zero-padded to the digits of N - 1.
        last=$((TILES - 1))
        tiles=()
        for ((i = 0; i < TILES; i++)); do
            tiles+=("$WORK_DIR/tile-$(printf "%0${#last}d" "$i").exr")
        done
        "$GPU_RENDER" merge "${tiles[@]}" -o "$output"
        ;;
    frames)
        default_name='frames/frame-{frame}.png'
        export FRAME_NAME="${FRAME_NAME:-$default_name}"
        mkdir -p "$(dirname "$FRAME_NAME")"
        parallel --jobs "$jobs" --halt soon,fail=1 render_one {} {%} ::: $(seq "$3" "$4")
        ;;
    *)
        usage
        ;;
esac
