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
# SET=e makes the fifth set (made after the first four had been looked at):
#
#   OUT/scenes_e/{quay,arterial}.glb              built in Blender, exported by its exporter
#   OUT/pairs_e/{quay,arterial}/                  `streaks stereo` pairs of them
#   OUT/other_config_e/                           3 samples of other_config_e.toml (seed 81)
#   OUT/heldback_e/                               24 default-config samples (seed 48900), a
#                                                 fifth held-back split
#
# SET=f makes the sixth set (made after the first five had been looked at):
#
#   OUT/scenes_f/{tramway,forecourt}.glb          built in Blender, exported by its exporter
#   OUT/pairs_f/{tramway,forecourt}/              `streaks stereo` pairs of them
#   OUT/other_config_f/                           3 samples of other_config_f.toml (seed 91)
#   OUT/heldback_f/                               24 default-config samples (seed 49900), a
#                                                 sixth held-back split
#
# SET=g makes the seventh set (made after the first six had been looked at):
#
#   OUT/scenes_g/{toll_plaza,close}.glb           built in Blender, exported by its exporter
#   OUT/pairs_g/{toll_plaza,close}/               `streaks stereo` pairs of them
#   OUT/other_config_g/                           3 samples of other_config_g.toml (seed 101)
#   OUT/heldback_g/                               24 default-config samples (seed 50900), a
#                                                 seventh held-back split
#
# SET=h makes the eighth set (made after the first seven had been looked at):
#
#   OUT/scenes_h/{bus_station,car_park_deck}.glb  built in Blender, exported by its exporter
#   OUT/pairs_h/{bus_station,car_park_deck}/      `streaks stereo` pairs of them
#   OUT/other_config_h/                           3 samples of other_config_h.toml (seed 111)
#   OUT/heldback_h/                               24 default-config samples (seed 51900), an
#                                                 eighth held-back split
#
# SET=i makes the ninth set (made after the first eight had been looked at):
#
#   OUT/scenes_i/{hotel_front,tunnel_portal}.glb  built in Blender, exported by its exporter
#   OUT/pairs_i/{hotel_front,tunnel_portal}/      `streaks stereo` pairs of them
#   OUT/other_config_i/                           3 samples of other_config_i.toml (seed 121)
#   OUT/heldback_i/                               24 default-config samples (seed 52900), a
#                                                 ninth held-back split
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

# The set's folders: scenes/ and pairs/ for the first, scenes_b/ and pairs_b/ for the second, ...
suffix=""
[[ "$set_name" == "a" ]] || suffix="_$set_name"
case "$set_name" in
    a | b | c | d | e | f | g | h | i) ;;
    *)
        echo "SET must be a, b, c, d, e, f, g, h or i, not $set_name" >&2
        exit 2
        ;;
esac

# Builds the set's Blender scenes into OUT/scenes$suffix.
build() {
    mkdir -p -- "$out/scenes$suffix" "$out/pairs$suffix"
    echo "$(stamp) building the Blender scenes of set $set_name"
    "$blender_python" "$here/blender_streets.py" "$out/scenes$suffix" --set "$set_name"
}

# pair NAME FLAGS...: the `streaks stereo` pair (64 spp) of the built scene NAME.
pair() {
    local name=$1
    shift
    echo "$(stamp) $name: $*"
    "$streaks" stereo "$out/scenes$suffix/$name.glb" -o "$out/pairs$suffix/$name" --spp 64 "$@"
}

# samples NAME FLAGS...: generated samples (8-bit images, truth and masks, not denoised).
samples() {
    local name=$1
    shift
    echo "$(stamp) $name: $*"
    "$streaks" dataset generate -o "$out/$name" --denoise off --outputs images,gt,masks "$@"
}

build
case "$set_name" in
    a)
        pair hill_bend --width 640 --height 480 --baseline 0.12 --exposure 5.5 --seed 1
        pair crossing --width 800 --height 450 --baseline 0.30 --sensor automotive_hdr --seed 1
        pair tabletop --width 640 --height 480 --baseline 0.06 --exposure 2 --seed 1
        samples other_config --config "$here/other_config.toml" --count 3 --seed 77 \
            --width 720 --height 400 --spp 24
        samples dry_config --config "$here/dry_config.toml" --count 4 --seed 78 \
            --width 640 --height 360 --spp 16
        samples heldback --seed 44900 --count 24 --width 480 --height 288 --spp 16
        ;;
    b)
        pair roundabout --width 640 --height 400 --baseline 0.20 --sensor automotive_linear \
            --seed 2
        pair avenue --width 720 --height 405 --baseline 0.15 --exposure 2.5 --seed 2
        pair shelf --width 640 --height 480 --baseline 0.05 --exposure 2 --seed 2
        samples heldback_b --seed 45900 --count 24 --width 400 --height 256 --spp 16
        ;;
    c)
        pair underpass --width 704 --height 396 --baseline 0.25 --exposure 4.5 --seed 3
        # sensor_c.toml: a 10-bit camera on the lorry.
        pair hillside --width 560 --height 420 --baseline 0.54 --sensor "$here/sensor_c.toml" \
            --seed 3
        pair daylight_street --width 640 --height 384 --baseline 0.40 --exposure -3.5 --seed 3
        samples other_config_c --config "$here/other_config_c.toml" --count 4 --seed 79 \
            --width 576 --height 320 --spp 24
        samples heldback_c --seed 46900 --count 24 --width 448 --height 256 --spp 16
        ;;
    d)
        pair bridge --width 768 --height 384 --baseline 0.35 --exposure 4 --seed 4
        pair square --width 600 --height 400 --baseline 0.18 --exposure 3.5 --seed 4
        samples other_config_d --config "$here/other_config_d.toml" --count 3 --seed 80 \
            --width 640 --height 352 --spp 24
        samples heldback_d --seed 47900 --count 24 --width 512 --height 288 --spp 16
        ;;
    e)
        pair quay --width 656 --height 368 --baseline 0.22 --exposure 4.75 --seed 5
        # sensor_e.toml: a 14-bit large-pixel camera on an SUV.
        pair arterial --width 720 --height 360 --baseline 0.32 --sensor "$here/sensor_e.toml" \
            --seed 5
        samples other_config_e --config "$here/other_config_e.toml" --count 3 --seed 81 \
            --width 608 --height 336 --spp 24
        samples heldback_e --seed 48900 --count 24 --width 464 --height 272 --spp 16
        ;;
    f)
        pair tramway --width 688 --height 400 --baseline 0.24 --exposure 3.75 --seed 6
        # sensor_f.toml: a 16-bit dual-gain camera behind a dirty windscreen on a van.
        pair forecourt --width 600 --height 336 --baseline 0.28 --sensor "$here/sensor_f.toml" \
            --seed 6
        samples other_config_f --config "$here/other_config_f.toml" --count 3 --seed 91 \
            --width 544 --height 304 --spp 24
        samples heldback_f --seed 49900 --count 24 --width 464 --height 272 --spp 16
        ;;
    g)
        # sensor_g.toml: a 12-bit large-pixel camera with a fast lens on a saloon.
        pair toll_plaza --width 784 --height 352 --baseline 0.38 \
            --sensor "$here/sensor_g.toml" --seed 7
        pair close --width 512 --height 384 --baseline 0.10 --exposure 6.5 --seed 7
        samples other_config_g --config "$here/other_config_g.toml" --count 3 --seed 101 \
            --width 592 --height 320 --spp 24
        samples heldback_g --seed 50900 --count 24 --width 480 --height 272 --spp 16
        ;;
    h)
        pair bus_station --width 736 --height 384 --baseline 0.16 --exposure 3 --seed 8
        # sensor_h.toml: a 12-bit camera with a slow lens behind a tinted windscreen on a van.
        pair car_park_deck --width 624 --height 416 --baseline 0.27 \
            --sensor "$here/sensor_h.toml" --seed 8
        samples other_config_h --config "$here/other_config_h.toml" --count 3 --seed 111 \
            --width 560 --height 304 --spp 24
        samples heldback_h --seed 51900 --count 24 --width 496 --height 288 --spp 16
        ;;
    i)
        pair hotel_front --width 752 --height 400 --baseline 0.14 --exposure 2.75 --seed 9
        # sensor_i.toml: a 12-bit camera with small low-noise pixels on a lorry.
        pair tunnel_portal --width 672 --height 384 --baseline 0.42 \
            --sensor "$here/sensor_i.toml" --seed 9
        samples other_config_i --config "$here/other_config_i.toml" --count 3 --seed 121 \
            --width 624 --height 336 --spp 24
        samples heldback_i --seed 52900 --count 24 --width 512 --height 272 --spp 16
        ;;
esac
echo "$(stamp) done: $out (set $set_name)"
