#!/usr/bin/env bash
# Wall time of one whole render against N processes rendering one tile each at the same
# time plus their merge, alternating the two, on one backend; prints every run and the
# medians and their ratio. Used for the tiles figures in BENCHMARKS.md:
#
#   scripts/bench-tiles.sh [SCENE] [BACKEND] [PROCESSES] [RUNS] [extra options...]
#   scripts/bench-tiles.sh scenes/showcase.toml cpu 2 5 --width 960 --height 540
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scene=${1:-scenes/showcase.toml}
backend=${2:-cpu}
processes=${3:-2}
runs=${4:-5}
shift $(($# < 4 ? $# : 4))
extra=("$@")
bin=target/release/gpu-render
[ -x "$bin" ] || cargo build --release --quiet
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$(now)" 'BEGIN {printf "%.3f", b - a}'; }
whole() {
    "$bin" "$scene" --backend "$backend" "${extra[@]}" -q -o "$work/whole.png"
}
tiled() {
    local pids=() i
    for ((i = 0; i < processes; i++)); do
        "$bin" "$scene" --backend "$backend" "${extra[@]}" -q \
            --tile "$i/$processes" -o "$work/tile-{tile}.exr" &
        pids+=($!)
    done
    for pid in "${pids[@]}"; do wait "$pid"; done
    "$bin" merge "$work"/tile-*.exr -q -o "$work/merged.png"
}
median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

whole_times=() tiled_times=()
for ((run = 0; run < runs; run++)); do
    start=$(now); whole; whole_times+=("$(elapsed "$start")")
    start=$(now); tiled; tiled_times+=("$(elapsed "$start")")
    rm -f "$work"/tile-*.exr
    echo "run $run: whole ${whole_times[-1]} s, $processes tiles + merge ${tiled_times[-1]} s"
done
cmp "$work/whole.png" "$work/merged.png" && echo "merged PNG equals the whole render byte for byte"
w=$(printf '%s\n' "${whole_times[@]}" | median)
t=$(printf '%s\n' "${tiled_times[@]}" | median)
echo "median: whole $w s, $processes tiles + merge $t s, speed-up $(awk -v w="$w" -v t="$t" 'BEGIN {printf "%.2f", w / t}')x"
