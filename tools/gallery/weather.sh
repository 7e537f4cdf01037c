#!/usr/bin/env bash
# The README's weather gallery: one generated street (dataset seed $SEED, sample 0) dry, in
# drizzle, in heavy rain and in fog, each as its camera (the automotive_hdr sensor, 1/50 s, the
# rig at 29 km/h) sees it, beside its ground-truth disparity and (rain) its rain mask or (fog)
# its transmittance. The weather is drawn in its own random streams, so the four configs give the
# same street. Writes docs/images/weather_{dry,drizzle,heavy,fog}.png.
#
#   bash tools/gallery/weather.sh   # `streaks` from PATH (or STREAKS=path); WEATHERS="heavy fog" for some
set -euo pipefail
cd "$(dirname "$0")/../.."
streaks="${STREAKS:-streaks}"
seed="${SEED:-3}"
spp="${SPP:-64}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for weather in ${WEATHERS:-dry drizzle heavy fog}; do
    start=$(date +%s)
    "$streaks" dataset generate -o "$work/$weather" --config "tools/gallery/$weather.toml" \
        --count 1 --seed "$seed" --width 640 --height 384 --spp "$spp"
    "$streaks" dataset preview "$work/$weather/samples/000000" \
        -o "docs/images/weather_$weather.png"
    echo "$weather: $(($(date +%s) - start)) s"
done
