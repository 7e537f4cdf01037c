#!/usr/bin/env bash
# CI check: streaks render against Mitsuba 3 on scenes/crosscheck.gltf, with the noise test of
# tools/mitsuba/README.md, then on the same scene with the glass pane of glass_pane.py
# (KHR_materials_transmission with a volume: Mitsuba's dielectric) at max depth 8, then on its
# road and wall lit by the environment map of env_scene.py only (Mitsuba's envmap; about 5 s),
# then on the whole scene in the homogeneous fog of fog_scene.py (Mitsuba's volpath; about 15 s).
# Exits 0 on agreement, 1 on disagreement, 2 when it cannot run.
# Environment: STREAKS (the binary; default target/debug/streaks, built with cargo build),
# CROSSCHECK_SPP (default 64), CROSSCHECK_WIDTH/HEIGHT (default 160x120), CROSSCHECK_K (4).
# Extra arguments go to the first crosscheck.py run (e.g. another scene path).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
cd "$repo"
if ! python3 -c "import mitsuba" 2>/dev/null; then
    echo "ci_check: mitsuba is not installed (pip install -r tools/mitsuba/requirements.txt)" >&2
    exit 2
fi
if [ -z "${STREAKS:-}" ]; then
    cargo build --bin streaks >&2
fi
streaks="${STREAKS:-$repo/target/debug/streaks}"
status=0
python3 "$here/crosscheck.py" --ci --streaks "$streaks" \
    --spp "${CROSSCHECK_SPP:-64}" --width "${CROSSCHECK_WIDTH:-160}" \
    --height "${CROSSCHECK_HEIGHT:-120}" --k "${CROSSCHECK_K:-4}" \
    --out "$repo/target/crosscheck/ci" "$@" || status=$?
# One more scene at CI's size, spp and k: SCENE MAX_DEPTH OUT then regions.
check_scene() {
    local scene="$1" depth="$2" out="$3"
    shift 3
    python3 "$here/crosscheck.py" "$scene" --camera cam --streaks "$streaks" \
        --max-depth "$depth" --spp "${CROSSCHECK_SPP:-64}" --width "${CROSSCHECK_WIDTH:-160}" \
        --height "${CROSSCHECK_HEIGHT:-120}" --k "${CROSSCHECK_K:-4}" \
        --out "$repo/target/crosscheck/$out" "$@" || status=$?
}
python3 "$here/glass_pane.py" "$repo/target/crosscheck/glass" >&2
check_scene "$repo/target/crosscheck/glass/glass_crosscheck.gltf" 8 ci_glass \
    --region pane=0.2,0.22,0.52,0.6 --region road=0,0.7,1,1 --region wall=0.6,0.1,0.95,0.5
python3 "$here/env_scene.py" "$repo/target/crosscheck/env" >&2
check_scene "$repo/target/crosscheck/env/env_crosscheck.gltf" 4 ci_env \
    --region top=0,0,1,0.06 --region wall=0.1,0.1,0.9,0.45 --region road=0,0.62,1,1 \
    --region streak=0.35,0.7,0.65,1
python3 "$here/fog_scene.py" "$repo/target/crosscheck/fog" >&2
check_scene "$repo/target/crosscheck/fog/fog_crosscheck.gltf" 4 ci_fog \
    --region sky=0,0,1,0.3 --region wall=0.45,0.05,1,0.5 --region road=0,0.6,1,1 \
    --region halo=0.55,0.05,0.8,0.3 --region lamp_halo=0.25,0.2,0.45,0.45
exit "$status"
