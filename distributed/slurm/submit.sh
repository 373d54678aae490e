#!/usr/bin/env bash
# Submits a tile array and the merge that waits for it:
#
#   SCENE=scene.toml TILES=16 OUTPUT=final.png distributed/slurm/submit.sh
#   SCENE=orbit.toml MODE=frames FRAMES=49 distributed/slurm/submit.sh
#
# With BACKEND=gpu each task asks for one GPU (--gres=gpu:1). Other sbatch options
# (partition, time limit) go in SBATCH_ARGS. Prints the job ids.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
: "${SCENE:?set SCENE to the scene file}"
# shellcheck disable=SC2206
options=(--parsable --export=ALL ${SBATCH_ARGS:-})
if [ "${BACKEND:-auto}" = gpu ]; then
    options+=(--gres=gpu:1)
fi
case "${MODE:-tiles}" in
    tiles)
        : "${TILES:?set TILES to the tile count}" "${OUTPUT:?set OUTPUT to the merged image}"
        export TILES
        array=$(sbatch "${options[@]}" --array="0-$((TILES - 1))" "$here/render.sbatch")
        echo "tiles: job $array"
        merge=$(sbatch --parsable --export=ALL ${SBATCH_ARGS:-} \
            --dependency="afterok:${array%%;*}" "$here/merge.sbatch")
        echo "merge: job $merge"
        ;;
    frames)
        : "${FRAMES:?set FRAMES to the frame count}"
        array=$(sbatch "${options[@]}" --array="0-$((FRAMES - 1))" "$here/render.sbatch")
        echo "frames: job $array"
        ;;
    *)
        echo "MODE must be tiles or frames, got ${MODE}" >&2
        exit 2
        ;;
esac
