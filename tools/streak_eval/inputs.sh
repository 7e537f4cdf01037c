#!/usr/bin/env bash
# Makes the outside evaluation inputs of streak-robust stereo (tools/streak_eval/README.md)
# into one folder:
#
#   tools/streak_eval/inputs.sh [OUT]          (OUT defaults to target/streak-eval)
#
#   OUT/scenes/{hill_bend,crossing,tabletop}.glb  built in Blender, exported by its exporter
#   OUT/pairs/{hill_bend,crossing,tabletop}/      `streaks stereo` pairs of them
#   OUT/other_config/                             3 samples of other_config.toml (seed 77)
#   OUT/dry_config/                               4 samples of dry_config.toml (seed 78)
#   OUT/heldback/                                 24 default-config samples (seed 44900), the
#                                                 held-back split no parameter choice sees
#
# SET=b makes the second set instead (made after the first had been looked at):
#
#   OUT/scenes_b/{roundabout,avenue,shelf}.glb    built in Blender, exported by its exporter
#   OUT/pairs_b/{roundabout,avenue,shelf}/        `streaks stereo` pairs of them
#   OUT/heldback_b/                               24 default-config samples (seed 45900), a
#                                                 new held-back split
#
# SET=c makes the third set (made after the first two had been looked at):
#
#   OUT/scenes_c/{underpass,hillside,daylight_street}.glb  built in Blender, exported by it
#   OUT/pairs_c/{underpass,hillside,daylight_street}/      `streaks stereo` pairs of them
#   OUT/other_config_c/                           4 samples of other_config_c.toml (seed 79)
#   OUT/heldback_c/                               24 default-config samples (seed 46900), a
#                                                 third held-back split
#
# SET=d makes the fourth set (made after the first three had been looked at):
#
#   OUT/scenes_d/{bridge,square}.glb              built in Blender, exported by its exporter
#   OUT/pairs_d/{bridge,square}/                  `streaks stereo` pairs of them
#   OUT/other_config_d/                           3 samples of other_config_d.toml (seed 80)
#   OUT/heldback_d/                               24 default-config samples (seed 47900), a
#                                                 fourth held-back split
#
# BLENDER_PYTHON: the Python with bpy 5.0 (default target/blender-venv/bin/python);
# STREAKS: the streaks binary (default target/release/streaks). Run from the repository root.
# Evaluation-only inputs: no parameter may be tuned on them.
set -euo pipefail

out="${1:-target/streak-eval}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
blender_python="${BLENDER_PYTHON:-target/blender-venv/bin/python}"
streaks="${STREAKS:-target/release/streaks}"
set_name="${SET:-a}"

stamp() { date -u +%H:%M:%S; }

if [[ "$set_name" == "b" ]]; then
    mkdir -p -- "$out/scenes_b" "$out/pairs_b"
    echo "$(stamp) building the second set's Blender scenes"
    "$blender_python" "$here/blender_streets.py" "$out/scenes_b" --set b

    echo "$(stamp) roundabout: 640x400, 64 spp, baseline 0.20 m, automotive_linear sensor"
    "$streaks" stereo "$out/scenes_b/roundabout.glb" -o "$out/pairs_b/roundabout" \
        --width 640 --height 400 --spp 64 --baseline 0.20 --sensor automotive_linear --seed 2

    echo "$(stamp) avenue: 720x405, 64 spp, baseline 0.15 m, +2.5 EV"
    "$streaks" stereo "$out/scenes_b/avenue.glb" -o "$out/pairs_b/avenue" \
        --width 720 --height 405 --spp 64 --baseline 0.15 --exposure 2.5 --seed 2

    echo "$(stamp) shelf: 640x480, 64 spp, baseline 0.05 m, +2 EV"
    "$streaks" stereo "$out/scenes_b/shelf.glb" -o "$out/pairs_b/shelf" \
        --width 640 --height 480 --spp 64 --baseline 0.05 --exposure 2 --seed 2

    echo "$(stamp) heldback_b: 24 samples of the default config, seed 45900, 400x256, 16 spp"
    "$streaks" dataset generate -o "$out/heldback_b" --seed 45900 --count 24 \
        --width 400 --height 256 --spp 16 --denoise off --outputs images,gt,masks

    echo "$(stamp) done: $out (second set)"
    exit 0
elif [[ "$set_name" == "c" ]]; then
    mkdir -p -- "$out/scenes_c" "$out/pairs_c"
    echo "$(stamp) building the third set's Blender scenes"
    "$blender_python" "$here/blender_streets.py" "$out/scenes_c" --set c

    echo "$(stamp) underpass: 704x396, 64 spp, baseline 0.25 m, +4.5 EV"
    "$streaks" stereo "$out/scenes_c/underpass.glb" -o "$out/pairs_c/underpass" \
        --width 704 --height 396 --spp 64 --baseline 0.25 --exposure 4.5 --seed 3

    echo "$(stamp) hillside: 560x420, 64 spp, baseline 0.54 m, sensor_c.toml (a 10-bit camera)"
    "$streaks" stereo "$out/scenes_c/hillside.glb" -o "$out/pairs_c/hillside" \
        --width 560 --height 420 --spp 64 --baseline 0.54 --sensor "$here/sensor_c.toml" --seed 3

    echo "$(stamp) daylight_street: 640x384, 64 spp, baseline 0.40 m, -3.5 EV (sunlit, dry)"
    "$streaks" stereo "$out/scenes_c/daylight_street.glb" -o "$out/pairs_c/daylight_street" \
        --width 640 --height 384 --spp 64 --baseline 0.40 --exposure -3.5 --seed 3

    echo "$(stamp) other_config_c: 4 samples, 576x320, 24 spp"
    "$streaks" dataset generate -o "$out/other_config_c" --config "$here/other_config_c.toml" \
        --count 4 --seed 79 --width 576 --height 320 --spp 24 --denoise off \
        --outputs images,gt,masks

    echo "$(stamp) heldback_c: 24 samples of the default config, seed 46900, 448x256, 16 spp"
    "$streaks" dataset generate -o "$out/heldback_c" --seed 46900 --count 24 \
        --width 448 --height 256 --spp 16 --denoise off --outputs images,gt,masks

    echo "$(stamp) done: $out (third set)"
    exit 0
elif [[ "$set_name" == "d" ]]; then
    mkdir -p -- "$out/scenes_d" "$out/pairs_d"
    echo "$(stamp) building the fourth set's Blender scenes"
    "$blender_python" "$here/blender_streets.py" "$out/scenes_d" --set d

    echo "$(stamp) bridge: 768x384, 64 spp, baseline 0.35 m, +4 EV"
    "$streaks" stereo "$out/scenes_d/bridge.glb" -o "$out/pairs_d/bridge" \
        --width 768 --height 384 --spp 64 --baseline 0.35 --exposure 4 --seed 4

    echo "$(stamp) square: 600x400, 64 spp, baseline 0.18 m, +3.5 EV"
    "$streaks" stereo "$out/scenes_d/square.glb" -o "$out/pairs_d/square" \
        --width 600 --height 400 --spp 64 --baseline 0.18 --exposure 3.5 --seed 4

    echo "$(stamp) other_config_d: 3 samples, 640x352, 24 spp"
    "$streaks" dataset generate -o "$out/other_config_d" --config "$here/other_config_d.toml" \
        --count 3 --seed 80 --width 640 --height 352 --spp 24 --denoise off \
        --outputs images,gt,masks

    echo "$(stamp) heldback_d: 24 samples of the default config, seed 47900, 512x288, 16 spp"
    "$streaks" dataset generate -o "$out/heldback_d" --seed 47900 --count 24 \
        --width 512 --height 288 --spp 16 --denoise off --outputs images,gt,masks

    echo "$(stamp) done: $out (fourth set)"
    exit 0
elif [[ "$set_name" != "a" ]]; then
    echo "SET must be a, b, c or d, not $set_name" >&2
    exit 2
fi

mkdir -p -- "$out/scenes" "$out/pairs"

echo "$(stamp) building the Blender scenes"
"$blender_python" "$here/blender_streets.py" "$out/scenes"

echo "$(stamp) hill_bend: 640x480, 64 spp, baseline 0.12 m, +5.5 EV"
"$streaks" stereo "$out/scenes/hill_bend.glb" -o "$out/pairs/hill_bend" \
    --width 640 --height 480 --spp 64 --baseline 0.12 --exposure 5.5 --seed 1

echo "$(stamp) crossing: 800x450, 64 spp, baseline 0.30 m, automotive_hdr sensor"
"$streaks" stereo "$out/scenes/crossing.glb" -o "$out/pairs/crossing" \
    --width 800 --height 450 --spp 64 --baseline 0.30 --sensor automotive_hdr --seed 1

echo "$(stamp) tabletop: 640x480, 64 spp, baseline 0.06 m, +2 EV"
"$streaks" stereo "$out/scenes/tabletop.glb" -o "$out/pairs/tabletop" \
    --width 640 --height 480 --spp 64 --baseline 0.06 --exposure 2 --seed 1

echo "$(stamp) other_config: 3 samples, 720x400, 24 spp"
"$streaks" dataset generate -o "$out/other_config" --config "$here/other_config.toml" \
    --count 3 --seed 77 --width 720 --height 400 --spp 24 --denoise off \
    --outputs images,gt,masks

echo "$(stamp) dry_config: 4 samples, 640x360, 16 spp"
"$streaks" dataset generate -o "$out/dry_config" --config "$here/dry_config.toml" \
    --count 4 --seed 78 --width 640 --height 360 --spp 16 --denoise off \
    --outputs images,gt,masks

echo "$(stamp) heldback: 24 samples of the default config, seed 44900, 480x288, 16 spp"
"$streaks" dataset generate -o "$out/heldback" --seed 44900 --count 24 \
    --width 480 --height 288 --spp 16 --denoise off --outputs images,gt,masks

echo "$(stamp) done: $out"
