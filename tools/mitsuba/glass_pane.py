#!/usr/bin/env python3
"""Write scenes/crosscheck.gltf with a glass pane added, for a Mitsuba cross-check of the
transmission (KHR_materials_transmission with KHR_materials_volume: Mitsuba's `dielectric`).

The pane is a closed box 1.2 m x 1.4 m x 2 cm at z = -4, between the camera and the sphere
lamp, smooth white glass (transmission 1, roughness 0, ior 1.5, thicknessFactor 0.02). Its
vertices are in a second buffer, embedded as a data URI, so the scene still reads
scenes/crosscheck.bin; the written .gltf goes beside a copy of it.

    python3 tools/mitsuba/glass_pane.py target/glass
    python3 tools/mitsuba/crosscheck.py target/glass/glass_crosscheck.gltf --camera cam \\
        --width 160 --height 120 --spp 256 --max-depth 8 --region pane=0.2,0.22,0.52,0.6 \\
        --region road=0,0.7,1,1 --region wall=0.6,0.1,0.95,0.5

See tools/mitsuba/README.md for the result.
"""

from __future__ import annotations

import argparse
import base64
import json
import shutil
import struct
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BOX = (-0.9, 0.3, 0.6, 2.0, -4.02, -4.0)  # x0, x1, y0, y1, z0, z1


def box_triangles() -> tuple[list[tuple[float, ...]], list[tuple[float, ...]]]:
    """The box's non-indexed triangles, counter-clockwise seen from outside, with flat normals."""
    x0, x1, y0, y1, z0, z1 = BOX
    positions: list[tuple[float, ...]] = []
    normals: list[tuple[float, ...]] = []
    faces = [
        (((x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)), (0, 0, 1)),
        (((x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)), (0, 0, -1)),
        (((x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)), (0, -1, 0)),
        (((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)), (0, 1, 0)),
        (((x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)), (-1, 0, 0)),
        (((x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)), (1, 0, 0)),
    ]
    for (a, b, c, d), n in faces:
        for v in (a, b, c, a, c, d):
            positions.append(v)
            normals.append(n)
    return positions, normals


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", type=Path, help="folder for glass_crosscheck.gltf and its .bin")
    args = p.parse_args()
    scene = json.loads((REPO / "scenes" / "crosscheck.gltf").read_text())
    positions, normals = box_triangles()
    data = b"".join(struct.pack("<3f", *v) for v in positions + normals)
    n = len(positions)
    scene["buffers"].append(
        {
            "byteLength": len(data),
            "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode(),
        }
    )
    buffer, view, accessor = (len(scene[k]) for k in ("buffers", "bufferViews", "accessors"))
    buffer -= 1
    scene["bufferViews"] += [
        {"buffer": buffer, "byteOffset": 0, "byteLength": 12 * n},
        {"buffer": buffer, "byteOffset": 12 * n, "byteLength": 12 * n},
    ]
    x0, x1, y0, y1, z0, z1 = BOX
    scene["accessors"] += [
        {
            "bufferView": view,
            "componentType": 5126,
            "count": n,
            "type": "VEC3",
            "min": [x0, y0, z0],
            "max": [x1, y1, z1],
        },
        {"bufferView": view + 1, "componentType": 5126, "count": n, "type": "VEC3"},
    ]
    scene["materials"].append(
        {
            "name": "glass",
            "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
            "extensions": {
                "KHR_materials_transmission": {"transmissionFactor": 1},
                "KHR_materials_volume": {"thicknessFactor": 0.02},
            },
        }
    )
    primitive = {
        "attributes": {"POSITION": accessor, "NORMAL": accessor + 1},
        "material": len(scene["materials"]) - 1,
    }
    scene["meshes"].append({"name": "pane", "primitives": [primitive]})
    scene["nodes"].append({"name": "pane", "mesh": len(scene["meshes"]) - 1})
    scene["scenes"][0]["nodes"].append(len(scene["nodes"]) - 1)
    scene.setdefault("extensionsUsed", []).extend(
        ["KHR_materials_transmission", "KHR_materials_volume"]
    )
    args.out.mkdir(parents=True, exist_ok=True)
    shutil.copy(REPO / "scenes" / "crosscheck.bin", args.out / "crosscheck.bin")
    (args.out / "glass_crosscheck.gltf").write_text(json.dumps(scene, indent=1))
    print(args.out / "glass_crosscheck.gltf")


if __name__ == "__main__":
    main()
