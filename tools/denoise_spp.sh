#!/usr/bin/env bash
# How many samples a denoised dataset needs (docs/benchmarks.md, "Denoising", and
# docs/decisions/0056): the first COUNT samples of a dataset (seed SEED, the default config and
# size) generated raw at the default cap of 64 spp, denoised at 64, 32 and 16 spp, and once
# with REF_SPP fixed samples and no denoising as the reference; then each candidate's left image
# against the reference's (`streaks compare`: relative RMSE over the image and the road, the
# road's bias, fireflies, the largest 8x8 difference) and each generation's time.
#
#   bash tools/denoise_spp.sh   # `streaks` from PATH (or STREAKS=path); SEED, COUNT, REF_SPP, WORK
#
# Denoising needs Intel Open Image Denoise (`pip install pyoidn`, or OIDN_LIBRARY).
set -euo pipefail
cd "$(dirname "$0")/.."
streaks="${STREAKS:-streaks}"
seed="${SEED:-0}"
count="${COUNT:-1}"
ref_spp="${REF_SPP:-512}"
work="${WORK:-$(mktemp -d)}"
mkdir -p "$work"
generate() {
    local name="$1" start
    shift
    rm -rf "${work:?}/$name"
    start=$(date +%s)
    "$streaks" dataset generate -o "$work/$name" --count "$count" --seed "$seed" "$@" >/dev/null
    echo "$name: $(($(date +%s) - start)) s for $count pairs" >&2
}
generate raw64 --denoise off
generate den64 --denoise on
generate den32 --denoise on --spp 32
generate den16 --denoise on --spp 16
generate reference --denoise off --spp "$ref_spp" --noise-target off
for dir in "$work"/reference/samples/*/; do
    id=$(basename "$dir")
    for name in raw64 den64 den32 den16; do
        "$streaks" compare "$work/$name/samples/$id/im0.exr" "$dir/im0.exr" \
            --mask "road=$dir/road0.png" --json >"$work/$name-$id.json"
        python3 - "$work/$name-$id.json" "$name" "$id" <<'EOF'
import json
import sys

c = json.load(open(sys.argv[1]))
image, road = c["overall"], c["regions"][0]
block, fireflies = c["largest_block"], c["fireflies"]
print(
    f"{sys.argv[3]} {sys.argv[2]:6s} image {image['rel_rmse']:.3f}  road {road['rel_rmse']:.3f}"
    f" / {100 * road['rel_bias']:+.2f} %  fireflies {1e4 * fireflies['share_a_all']:.1f}"
    f" per 10,000  largest 8x8 difference {block['rel_diff']:+.1f} x the image mean at ({block['x0']}, {block['y0']})"
)
EOF
    done
done
