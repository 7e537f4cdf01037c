#!/usr/bin/env python3
"""Write scenes/crosscheck.gltf in homogeneous fog, for a Mitsuba cross-check of the fog
(Mitsuba's `volpath` with a `homogeneous` medium and an `hg` phase function: free flights in
one colour channel per path, next-event estimation from the fog with MIS, transmittance on
shadow rays).

The scene keeps the crosscheck scene's glossy wet road, diffuse wall, point light, emissive
sphere lamp and camera, and adds `scenes[0].extras.streaks.fog` with an RGB extinction
(bluer light is scattered more), albedo 0.9 and g = 0.7 (forward, as in real fog): the point
light and the lamp get halos, and the road's streaks are seen through the fog.

    python3 tools/mitsuba/fog_scene.py target/fog
    python3 tools/mitsuba/crosscheck.py target/fog/fog_crosscheck.gltf --camera cam \\
        --width 160 --height 120 --spp 64 --max-depth 4 --region sky=0,0,1,0.3 \\
        --region wall=0.45,0.05,1,0.5 --region road=0,0.6,1,1 --region halo=0.55,0.25,0.8,0.55

See tools/mitsuba/README.md for the result.
"""

from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
# Extinction per metre (R, G, B), single-scattering albedo and Henyey-Greenstein g.
FOG = {"sigma_t": [0.03, 0.04, 0.05], "albedo": 0.9, "g": 0.7}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", type=Path, help="folder for fog_crosscheck.gltf and its .bin")
    args = p.parse_args()
    scene = json.loads((REPO / "scenes" / "crosscheck.gltf").read_text())
    scene["scenes"][0]["extras"] = {
        "description": "crosscheck scene in homogeneous fog",
        "streaks": {"fog": FOG},
    }
    args.out.mkdir(parents=True, exist_ok=True)
    shutil.copy(REPO / "scenes" / "crosscheck.bin", args.out / "crosscheck.bin")
    (args.out / "fog_crosscheck.gltf").write_text(json.dumps(scene, indent=1))
    print(args.out / "fog_crosscheck.gltf")


if __name__ == "__main__":
    main()
