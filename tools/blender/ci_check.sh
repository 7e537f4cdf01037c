#!/usr/bin/env bash
# CI check: streaks render against Blender's Cycles on two scenes of tools/blender/scenes.py
# (tools/blender/README.md): `diffuse`, as exported and as its Lambert variant (light units,
# emission, light transport), and `road_lambert` (a normal map through a Mapping node:
# KHR_texture_transform, MikkTSpace tangents, the normal map's orientation and Cycles'
# shading-normal rules).
# Exits 0 on agreement, 1 on disagreement, 2 when it cannot run (no bpy).
# Environment: BLENDER_PYTHON (a Python with bpy; default target/blender-venv/bin/python),
# STREAKS (the binary; default target/debug/streaks, built with cargo build),
# BLENDER_SPP (default 256), BLENDER_WIDTH/HEIGHT (default 160x120), BLENDER_K (4).
# Extra arguments go to crosscheck.py.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
cd "$repo"
python="${BLENDER_PYTHON:-$repo/target/blender-venv/bin/python}"
if ! "$python" -c "import bpy" >/dev/null 2>&1; then
    echo "ci_check: no bpy in $python (python3 -m venv target/blender-venv;" \
        "target/blender-venv/bin/pip install -r tools/blender/requirements.txt)" >&2
    exit 2
fi
if [ -z "${STREAKS:-}" ]; then
    cargo build --bin streaks >&2
fi
streaks="${STREAKS:-$repo/target/debug/streaks}"
status=0
"$python" "$here/crosscheck.py" diffuse --lambert --streaks "$streaks" \
    --spp "${BLENDER_SPP:-256}" --width "${BLENDER_WIDTH:-160}" \
    --height "${BLENDER_HEIGHT:-120}" --k "${BLENDER_K:-4}" \
    --out "$repo/target/blender/ci" "$@" || status=$?
"$python" "$here/crosscheck.py" road_lambert --streaks "$streaks" \
    --spp "${BLENDER_SPP:-256}" --width "${BLENDER_WIDTH:-160}" \
    --height "${BLENDER_HEIGHT:-120}" --k "${BLENDER_K:-4}" \
    --out "$repo/target/blender/ci_road" "$@" || status=$?
exit "$status"
