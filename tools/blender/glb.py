"""Reading and writing binary glTF (.glb) files, and the Lambert variant of an export.

The Lambert variant isolates the exporter's lights and emission from the material model: every
material that Cycles renders as a pure Lambertian (a Principled BSDF with Specular IOR Level 0,
metallic 0, no coat, transmission or textures) gets `extras.streaks = {"bsdf": "ggx", "kd":
the exported baseColorFactor, "ks": 0, "alpha": 1}`, which streaks renders as exactly
`kd / pi` (the paper models of docs/design.md), whatever glTF material extensions it honours.
Lights, emission, geometry and camera are the exporter's, unchanged.
"""

from __future__ import annotations

import json
import struct
from collections.abc import Iterable
from typing import Any

from scenes import Material

GLB_MAGIC = 0x46546C67  # "glTF"
CHUNK_JSON = 0x4E4F534A  # "JSON"
CHUNK_BIN = 0x004E4942  # "BIN\0"


def read_glb(data: bytes) -> tuple[dict[str, Any], bytes | None]:
    """The JSON document and the binary chunk (None when absent) of a .glb file."""
    if len(data) < 20:
        raise ValueError("not a glb: shorter than its header")
    magic, version, length = struct.unpack_from("<III", data, 0)
    if magic != GLB_MAGIC or version != 2 or length != len(data):
        raise ValueError(f"not a glTF 2 glb (magic {magic:#x}, version {version}, length)")
    offset, doc, binary = 12, None, None
    while offset < length:
        size, kind = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8 : offset + 8 + size]
        if kind == CHUNK_JSON:
            doc = json.loads(chunk.decode("utf-8"))
        elif kind == CHUNK_BIN:
            binary = chunk
        offset += 8 + size
    if doc is None:
        raise ValueError("glb without a JSON chunk")
    return doc, binary


def write_glb(doc: dict[str, Any], binary: bytes | None) -> bytes:
    """A .glb of `doc` and `binary` (JSON padded with spaces, binary with zeros, to 4 bytes)."""
    text = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), CHUNK_JSON) + text
    if binary is not None:
        padded = binary + b"\0" * (-len(binary) % 4)
        chunks += struct.pack("<II", len(padded), CHUNK_BIN) + padded
    return struct.pack("<III", GLB_MAGIC, 2, 12 + len(chunks)) + chunks


def is_lambertian(m: Material) -> bool:
    """Whether Cycles renders `m` as a pure Lambertian of its base colour."""
    return (
        m.specular_ior_level == 0.0
        and m.metallic == 0.0
        and m.coat_weight == 0.0
        and m.transmission == 0.0
        and m.normal_map is None
        and m.roughness_map is None
        and m.alpha_map is None
    )


def lambert_variant(doc: dict[str, Any], materials: Iterable[Material]) -> list[str]:
    """Gives every material of `doc` that is Lambertian in `materials` (matched by name) the
    streaks extras of an exact Lambertian; returns the names it changed."""
    lambertian = {m.name: m for m in materials if is_lambertian(m)}
    changed = []
    for mat in doc.get("materials", []):
        spec = lambertian.get(mat.get("name", ""))
        if spec is None:
            continue
        base = mat.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1.0, 1.0, 1.0, 1.0])
        extras = mat.setdefault("extras", {})
        extras["streaks"] = {
            "bsdf": "ggx",
            "kd": [float(c) for c in base[:3]],
            "ks": [0.0, 0.0, 0.0],
            "alpha": 1.0,
        }
        changed.append(spec.name)
    return changed
