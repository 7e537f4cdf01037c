"""Tests of tools/blender/build.py's pure parts (needs bpy, as CI's venv has)."""

import numpy as np
import pytest

pytest.importorskip("bpy")
from build import box_geometry, texture_pixels  # noqa: E402

from scenes import Texture  # noqa: E402


def test_the_normal_map_encodes_unit_normals_facing_out():
    px = texture_pixels(Texture("bumps", size=64))
    n = px[..., :3] * 2.0 - 1.0
    assert np.allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-6)
    assert (n[..., 2] > 0).all()
    # Flat (0, 0, 1) between the bumps, tilted on them.
    assert np.allclose(n[0, 0], (0.0, 0.0, 1.0))
    assert (n[..., 2] < 0.9).any()


def test_the_roughness_map_has_puddles_in_g_and_no_metal():
    px = texture_pixels(Texture("puddles", size=64))
    assert set(np.unique(px[..., 1]).round(3)) == {0.08, 0.7}
    assert (px[..., 2] == 0).all()


def test_the_fence_is_a_binary_mask():
    alpha = texture_pixels(Texture("fence", size=64))[..., 3]
    assert set(np.unique(alpha)) == {0.0, 1.0}
    assert 0.2 < alpha.mean() < 0.6


def test_unknown_textures_are_errors():
    with pytest.raises(ValueError):
        texture_pixels(Texture("marble"))


def test_box_faces_point_outward():
    verts, faces = box_geometry((0, 0, 0), (1, 2, 3))
    v = np.array(verts, dtype=float)
    centre = v.mean(axis=0)
    for f in faces:
        a, b, c = v[f[0]], v[f[1]], v[f[2]]
        normal = np.cross(b - a, c - a)
        assert np.dot(normal, v[list(f)].mean(axis=0) - centre) > 0
