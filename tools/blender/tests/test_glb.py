"""Tests of tools/blender/glb.py: .glb reading and writing, the Lambert variant."""

import struct

import pytest
from glb import is_lambertian, lambert_variant, read_glb, write_glb

from scenes import DIFFUSE, WET_STREET, Material


def test_write_then_read_gives_the_document_and_binary_back():
    doc = {"asset": {"version": "2.0"}, "materials": [{"name": "é"}]}
    binary = b"\x01\x02\x03\x04\x05"
    data = write_glb(doc, binary)
    assert len(data) % 4 == 0
    assert struct.unpack_from("<III", data, 0) == (0x46546C67, 2, len(data))
    back, bin_back = read_glb(data)
    assert back == doc
    assert bin_back == binary + b"\0\0\0"  # padded to 4 bytes, as the specification asks
    assert read_glb(write_glb(doc, None)) == (doc, None)


def test_read_rejects_what_is_not_a_glb():
    with pytest.raises(ValueError):
        read_glb(b"not a glb at all, really")
    data = bytearray(write_glb({"asset": {}}, None))
    data[0] = 0
    with pytest.raises(ValueError):
        read_glb(bytes(data))


def test_only_lambertian_materials_change():
    doc = {
        "materials": [
            {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
            {"name": "panel", "emissiveFactor": [1, 0.85, 0.6]},
            {"name": "unknown"},
        ]
    }
    changed = lambert_variant(doc, DIFFUSE.materials)
    assert changed == ["floor", "panel"]
    floor = doc["materials"][0]["extras"]["streaks"]
    assert floor == {"bsdf": "ggx", "kd": [0.5, 0.5, 0.5], "ks": [0.0, 0.0, 0.0], "alpha": 1.0}
    # No baseColorFactor: the glTF default, white.
    assert doc["materials"][1]["extras"]["streaks"]["kd"] == [1.0, 1.0, 1.0]
    assert "extras" not in doc["materials"][2]


def test_textured_or_specular_materials_are_not_lambertian():
    assert not any(is_lambertian(m) for m in WET_STREET.materials if m.name != "headlight")
    assert not is_lambertian(Material("default"))  # Specular IOR Level 0.5
    assert is_lambertian(Material("matte", specular_ior_level=0.0))
