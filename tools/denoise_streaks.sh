#!/usr/bin/env bash
# What denoising does to the paper's streak disparities (docs/benchmarks.md, "Denoising"): the
# main job's street as a stereo pair, converged (REF_SPP samples, another seed), at 64 spp raw,
# and at 64 and 16 spp denoised (`--denoise`, which needs Intel Open Image Denoise: `pip install
# pyoidn`); each analysed (`--analyze`: per-row LK on the streaks) and matched by SGM
# (`streaks disparity` on its PNGs); then tools/streak_shift.py compares each with the
# converged pair.
#
#   bash tools/denoise_streaks.sh   # `streaks` from PATH (or STREAKS=path); HEIGHT, REF_SPP, WORK
set -euo pipefail
cd "$(dirname "$0")/.."
streaks="${STREAKS:-streaks}"
scene="${SCENE:-scenes/rainy_street.gltf}"
height="${HEIGHT:-240}"
ref_spp="${REF_SPP:-1024}"
work="${WORK:-$(mktemp -d)}"
mkdir -p "$work"
pair() {
    local dir="$1"
    shift
    local start
    start=$(date +%s)
    "$streaks" stereo "$scene" -o "$work/$dir" --height "$height" --analyze "$@" >/dev/null
    "$streaks" disparity "$work/$dir/im0.png" "$work/$dir/im1.png" -o "$work/$dir/sgm.pfm"
    echo "$dir: $(($(date +%s) - start)) s" >&2
}
pair reference --spp "$ref_spp" --seed 100
pair raw64 --spp 64
pair denoised64 --spp 64 --denoise
pair denoised16 --spp 16 --denoise
python3 tools/streak_shift.py "$work/reference" "$work/raw64" "$work/denoised64" \
    "$work/denoised16"
