"""Tests of tools/blender/scenes.py: the scene specifications and the camera projection."""

import math

import pytest

from scenes import (
    DIFFUSE,
    SCENES,
    Camera,
    Region,
    cycles_bounces,
    project,
    quad_xy,
    quad_xz,
    region_fractions,
)

CAM = Camera(location=(0.0, -5.0, 1.0), target=(0.0, 0.0, 1.0), yfov_deg=90.0)


def test_the_target_projects_to_the_image_centre():
    for spec in SCENES.values():
        x, y = project(spec.camera, spec.camera.target, spec.width / spec.height)
        assert x == pytest.approx(0.5) and y == pytest.approx(0.5)


def test_projection_is_right_and_down():
    # yfov 90 degrees: at distance 5 the image spans +-5 vertically and +-5 aspect horizontally.
    assert project(CAM, (0.0, 0.0, 6.0), 1.0) == pytest.approx((0.5, 0.0))
    assert project(CAM, (0.0, 0.0, -4.0), 1.0) == pytest.approx((0.5, 1.0))
    assert project(CAM, (10.0, 0.0, 1.0), 2.0) == pytest.approx((1.0, 0.5))
    assert project(CAM, (-2.5, 0.0, 1.0), 1.0) == pytest.approx((0.25, 0.5))


def test_points_behind_the_camera_are_errors():
    with pytest.raises(ValueError):
        project(CAM, (0.0, -6.0, 1.0), 1.0)


def test_region_fractions_bound_the_projection_and_clip():
    r = Region("r", quad_xz(-2.5, -1.5, 2.5, 3.5, 0.0), "", inset=0.0)
    assert region_fractions(CAM, r, 1.0) == pytest.approx((0.25, 0.25, 0.75, 0.75))
    inset = Region("r", r.points, "", inset=0.1)
    assert region_fractions(CAM, inset, 1.0) == pytest.approx((0.3, 0.3, 0.7, 0.7))
    wide = Region("w", quad_xz(-20.0, -1.5, 2.5, 3.5, 0.0), "")
    assert region_fractions(CAM, wide, 1.0)[0] == 0.0
    outside = Region("o", quad_xz(20.0, 0.0, 30.0, 1.0, 0.0), "")
    with pytest.raises(ValueError):
        region_fractions(CAM, outside, 1.0)


@pytest.mark.parametrize("spec", SCENES.values(), ids=SCENES.keys())
def test_every_scene_is_consistent(spec):
    aspect = spec.width / spec.height
    names = [r.name for r in spec.regions]
    assert len(set(names)) == len(names), "region names are unique"
    for r in spec.regions:
        x0, y0, x1, y1 = region_fractions(spec.camera, r, aspect)
        # At least 4 pixels of the default image, so streaks compare has a region to judge.
        assert (x1 - x0) * spec.width * (y1 - y0) * spec.height >= 4, r.name
    for mesh in spec.meshes:
        spec.material(mesh.material)
        assert mesh.kind in ("quad", "box", "sphere")
        if mesh.kind == "sphere":
            assert mesh.radius > 0
    for light in spec.lights:
        assert light.kind in ("point", "spot", "sun") and light.power > 0
    assert spec.max_depth >= 2 and 0 < spec.tolerance < 1


def test_the_ci_scene_is_exact_in_both_renderers():
    # The CI gates on the noise test, so the diffuse scene must have the same expectation in
    # both: Lambertian materials (Specular IOR Level 0) and a hard-edged spot (blend 0: the
    # exported inner cone equals the outer, and Cycles' smoothstep is a step).
    assert all(m.specular_ior_level == 0.0 and m.metallic == 0.0 for m in DIFFUSE.materials)
    spots = [light for light in DIFFUSE.lights if light.kind == "spot"]
    assert spots and all(s.spot_blend == 0.0 for s in spots)
    assert {light.kind for light in DIFFUSE.lights} == {"point", "spot", "sun"}
    assert any(m.emission_strength > 0 for m in DIFFUSE.materials)
    assert all(r.gate for r in DIFFUSE.regions)


def test_the_spot_blend_scene_reports_its_penumbra_only():
    spec = SCENES["spot_blend"]
    gates = {r.name: r.gate for r in spec.regions}
    assert gates["spot_pen"] is False and gates["point"] is True


def test_quads_face_their_documented_side():
    def normal(q):
        a, b, c = q[0], q[1], q[2]
        u = [b[i] - a[i] for i in range(3)]
        v = [c[i] - a[i] for i in range(3)]
        return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])

    nx, ny, nz = normal(quad_xy(0, 0, 1, 1, 0))
    assert nz > 0 and nx == 0 and ny == 0
    nx, ny, nz = normal(quad_xz(0, 0, 1, 1, 0))
    assert ny < 0 and nx == 0 and nz == 0


def test_cycles_bounces_follow_mitsubas_depth():
    assert cycles_bounces(2) == 0  # direct light only
    assert cycles_bounces(4) == 2
    with pytest.raises(ValueError):
        cycles_bounces(1)


def test_spot_region_lies_inside_the_core():
    # The spot region's corners are within the inner cone (fully lit in both renderers).
    spot = next(light for light in DIFFUSE.lights if light.kind == "spot")
    region = next(r for r in DIFFUSE.regions if r.name == "spot")
    half = math.radians(spot.spot_size_deg / 2)
    for p in region.points:
        d = [p[i] - spot.location[i] for i in range(3)]
        cos = -d[2] / math.sqrt(sum(c * c for c in d))
        assert cos > math.cos(half * (1 - spot.spot_blend) * 0.9)
