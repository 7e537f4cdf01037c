#!/usr/bin/env bash
# Scores streak-robust stereo on the evaluation inputs that inputs.sh made:
#
#   tools/streak_eval/evaluate.sh [IN [OUT]]    (IN defaults to target/streak-eval, OUT to IN/results)
#
# For each of heldback/, other_config/, dry_config/ and pairs/ (hill_bend, crossing, tabletop):
#   OUT/bench-NAME/             `streaks benchmark` of sgm, sgm-streaks (and opencv-sgbm with
#                               OPENCV_PYTHON), with the breakdown by condition, streak length
#                               and distance (report.json, index.html)
#   OUT/repair-NAME.json        `streaks train-repair --evaluate`: phantom holes, off-road bad-2
#                               and densities before and after, the streak mask's scores
# then prints one table (summary.py). With SET=b it scores the second set instead (heldback_b/
# and pairs_b/: roundabout, avenue, shelf), made after the first set had been looked at; with
# SET=c the third set (heldback_c/, other_config_c/ and pairs_c/: underpass, hillside,
# daylight_street), made after the first two had been looked at; with SET=d the fourth
# (heldback_d/, other_config_d/ and pairs_d/: bridge, square), made after the first three;
# with SET=e the fifth (heldback_e/, other_config_e/ and pairs_e/: quay, arterial), made after
# the first four; with SET=f the sixth (heldback_f/, other_config_f/ and pairs_f/: tramway,
# forecourt), made after the first five; with SET=g the seventh (heldback_g/, other_config_g/
# and pairs_g/: toll_plaza, close), made after the first six; with SET=h the eighth
# (heldback_h/, other_config_h/ and pairs_h/: bus_station, car_park_deck), made after the
# first seven; with SET=i the ninth (heldback_i/, other_config_i/ and pairs_i/: hotel_front,
# tunnel_portal), made after the first eight.
#
# STREAKS: the binary (default target/release/streaks); OPENCV_PYTHON: a Python with
# opencv-python-headless (tools/opencv/requirements.txt) to add OpenCV's StereoSGBM.
# Evaluation only: no parameter may be tuned on these figures.
set -euo pipefail

in="${1:-target/streak-eval}"
out="${2:-$in/results}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
streaks="${STREAKS:-target/release/streaks}"

methods=(--method sgm sgm-streaks)
if [[ -n "${OPENCV_PYTHON:-}" ]]; then
    methods+=(--method-cmd "opencv-sgbm=$OPENCV_PYTHON $here/../opencv/sgbm.py {left} {right} {out}")
fi

mkdir -p -- "$out"
stamp() { date -u +%H:%M:%S; }

if [[ "${SET:-a}" == b ]]; then
    benches=(heldback_b pairs_b)
    repairs=(heldback_b pairs_b/roundabout pairs_b/avenue)
elif [[ "${SET:-a}" == c ]]; then
    benches=(heldback_c other_config_c pairs_c)
    repairs=(heldback_c other_config_c pairs_c/underpass pairs_c/hillside pairs_c/daylight_street)
elif [[ "${SET:-a}" == d ]]; then
    benches=(heldback_d other_config_d pairs_d)
    repairs=(heldback_d other_config_d pairs_d/bridge pairs_d/square)
elif [[ "${SET:-a}" == e ]]; then
    benches=(heldback_e other_config_e pairs_e)
    repairs=(heldback_e other_config_e pairs_e/quay pairs_e/arterial)
elif [[ "${SET:-a}" == f ]]; then
    benches=(heldback_f other_config_f pairs_f)
    repairs=(heldback_f other_config_f pairs_f/tramway pairs_f/forecourt)
elif [[ "${SET:-a}" == g ]]; then
    benches=(heldback_g other_config_g pairs_g)
    repairs=(heldback_g other_config_g pairs_g/toll_plaza pairs_g/close)
elif [[ "${SET:-a}" == h ]]; then
    benches=(heldback_h other_config_h pairs_h)
    repairs=(heldback_h other_config_h pairs_h/bus_station pairs_h/car_park_deck)
elif [[ "${SET:-a}" == i ]]; then
    benches=(heldback_i other_config_i pairs_i)
    repairs=(heldback_i other_config_i pairs_i/hotel_front pairs_i/tunnel_portal)
else
    benches=(heldback other_config dry_config pairs)
    repairs=(heldback other_config dry_config pairs/hill_bend pairs/crossing)
fi

for name in "${benches[@]}"; do
    echo "$(stamp) benchmark: $name"
    "$streaks" benchmark "$in/$name" "${methods[@]}" -o "$out/bench-$name"
done

for name in "${repairs[@]}"; do
    echo "$(stamp) repair figures: $name"
    "$streaks" train-repair --evaluate "$in/$name" --val-split all \
        -o "$out/repair-$(basename "$name").json"
done

python3 "$here/summary.py" "$out"
