"""streaks.Scene and streaks.Pair: a pair rendered in-process equals, file for file and bit for
bit, the one `streaks stereo` renders with the same seed and options; the ground truth follows
its documented rules; bad scenes and options raise StreaksError naming the file or keyword."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import streaks
from streaks import io

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "rainy_street_small.gltf"
TINY: dict[str, Any] = {"width": 48, "height": 32, "spp": 2, "seed": 3, "threads": 2}
"""A tiny pair: quick with a debug build."""


@pytest.fixture(scope="module")
def scene() -> streaks.Scene:
    return streaks.Scene.load(SCENE)


@pytest.fixture(scope="module")
def pair(scene: streaks.Scene) -> streaks.Pair:
    return scene.render_pair(**TINY)


def _command_flags(options: dict[str, Any]) -> list[str]:
    """The `streaks stereo` flags of keyword options (a bool is a switch, a tuple X,Y,Z)."""
    flags: list[str] = []
    for key, value in options.items():
        flag = f"--{key.replace('_', '-')}"
        if isinstance(value, bool):
            flags += [flag] if value else []
        elif isinstance(value, tuple):
            flags += [flag, ",".join(str(v) for v in value)]
        else:
            flags += [flag, str(value)]
    return flags


def _denoiser_available() -> bool:
    """Whether Intel Open Image Denoise loads: the denoising case is skipped without it (saying
    so), unless STREAKS_REQUIRE_OIDN is set (as CI does), which fails it."""
    try:
        streaks.Scene.load(SCENE).render(width=4, height=4, spp=1, denoise=True)
    except streaks.StreaksError as e:
        assert "STREAKS_REQUIRE_OIDN" not in os.environ, str(e)
        return False
    return True


def _same_folders(cli: Path, saved: Path) -> None:
    names = sorted(p.name for p in cli.iterdir())
    assert names == sorted(p.name for p in saved.iterdir())
    for name in names:
        assert (cli / name).read_bytes() == (saved / name).read_bytes(), name


def test_a_pair_equals_the_command_file_for_file(
    pair: streaks.Pair, streaks_bin: str, tmp_path: Path
) -> None:
    cli = tmp_path / "cli"
    subprocess.run(
        [streaks_bin, "stereo", str(SCENE), "-o", str(cli), *_command_flags(TINY)],
        check=True,
        capture_output=True,
        timeout=300,
    )
    saved = pair.save(tmp_path / "py")
    _same_folders(cli, saved)
    assert {"disp0.pfm", "im0.exr", "rig.json"} <= {p.name for p in cli.iterdir()}
    # The arrays are the numbers of the command's files, bit for bit.
    same = np.testing.assert_array_equal
    same(pair.disparity, io.read_pfm(cli / "disp0.pfm"))
    same(pair.disparity_right, io.read_pfm(cli / "disp1.pfm"))
    same(pair.depth, io.read_pfm(cli / "depth0.pfm"))
    same(pair.depth_right, io.read_pfm(cli / "depth1.pfm"))
    same(pair.left, io.read_exr(cli / "im0.exr")["rgb"])
    same(pair.right, io.read_exr(cli / "im1.exr")["rgb"])
    same(pair.streak_mask, io.read_png(cli / "streaks0.png") == 255)
    same(pair.streak_mask_right, io.read_png(cli / "streaks1.png") == 255)
    same(pair.road_mask, io.read_png(cli / "road0.png") == 255)
    same(pair.occlusion, io.read_png(cli / "occ0.png") == 255)
    same(pair.occlusion_right, io.read_png(cli / "occ1.png") == 255)
    same(pair.left_camera, io.read_png(cli / "im0.png"))
    same(pair.right_camera, io.read_png(cli / "im1.png"))
    assert pair.meta["rig"] == json.loads((cli / "rig.json").read_text())


@pytest.mark.parametrize(
    "options",
    [
        {"sensor": "automotive_linear", "exposure": 2.0},
        {"regularize": True, "max_depth": 3, "noise_target": 0.5, "camera": 0},
        {"shutter": 0.02, "rig_velocity": (3.0, 0.0, -1.0), "baseline": 0.2},
        {"denoise": True},
    ],
    ids=["sensor", "sampling", "motion", "denoise"],
)
def test_every_option_renders_as_the_command_does(
    scene: streaks.Scene, streaks_bin: str, tmp_path: Path, options: dict[str, Any]
) -> None:
    if options.get("denoise") and not _denoiser_available():
        pytest.skip("Intel Open Image Denoise is not available (pip install pyoidn)")
    cli = tmp_path / "cli"
    subprocess.run(
        [streaks_bin, "stereo", str(SCENE), "-o", str(cli), *_command_flags({**TINY, **options})],
        check=True,
        capture_output=True,
        timeout=300,
    )
    pair = scene.render_pair(**TINY, **options)
    _same_folders(cli, pair.save(tmp_path / "py"))
    if "sensor" in options:
        assert pair.sensor is not None
        np.testing.assert_array_equal(pair.sensor, io.read_exr(cli / "im0.exr")["sensor"])
        # The camera's image is developed from its DN, as the command's PNG is.
        np.testing.assert_array_equal(pair.left_camera, io.read_png(cli / "im0.png"))
    if options.get("denoise"):
        exr = io.read_exr(cli / "im0.exr")
        np.testing.assert_array_equal(pair.left, exr["rgb"])
        assert not np.array_equal(exr["raw"], exr["rgb"])


def test_the_arrays_follow_the_documented_conventions(pair: streaks.Pair) -> None:
    h, w = TINY["height"], TINY["width"]
    assert pair.left.shape == pair.right.shape == (h, w, 3)
    assert pair.left.dtype == np.float32
    for a in (pair.disparity, pair.disparity_right, pair.depth, pair.depth_right):
        assert a.shape == (h, w) and a.dtype == np.float32
    for m in (pair.streak_mask, pair.road_mask, pair.streak_mask_right, pair.road_mask_right):
        assert m.shape == (h, w) and m.dtype == np.bool_
    assert pair.sensor is None and pair.sensor_right is None
    # d = f b / Z where the pixel sees a surface, inf exactly where it sees none (the sky).
    rig = pair.meta["rig"]
    f, b = rig["intrinsics"]["focal_px"], rig["baseline"]
    assert b == pytest.approx(streaks.DEFAULT_BASELINE)
    hit = np.isfinite(pair.depth)
    np.testing.assert_array_equal(hit, np.isfinite(pair.disparity))
    assert hit.any() and (~hit).any(), "the street's camera sees both road and sky"
    np.testing.assert_allclose(pair.disparity[hit], f * b / pair.depth[hit], rtol=1e-6)
    assert not np.isnan(pair.disparity).any()
    assert rig["intrinsics"]["width"] == w and rig["intrinsics"]["height"] == h
    assert pair.road_mask.any() and pair.streak_mask.any()
    # Streaks are on the road: the renderer's masks say so for this scene.
    assert (pair.streak_mask & ~pair.road_mask).sum() <= pair.streak_mask.sum()
    settings = pair.meta["settings"]
    assert (settings["spp"], settings["width"], settings["height"]) == (2, w, h)
    assert pair.meta["seed"] == 3 and pair.meta["camera"] == "driver"
    assert pair.meta["timings"]["total_s"] >= pair.meta["timings"]["left_s"] > 0
    assert pair.meta["stats"]["samples"] == [w * h * 2, w * h * 2]


def test_the_same_seed_gives_the_same_pair_and_another_seed_another(
    scene: streaks.Scene, pair: streaks.Pair
) -> None:
    again = scene.render_pair(**TINY)
    np.testing.assert_array_equal(again.left, pair.left)
    np.testing.assert_array_equal(again.right, pair.right)
    other = scene.render_pair(**{**TINY, "seed": 4})
    assert not np.array_equal(other.left, pair.left)
    # The ground truth does not depend on the sampler's seed.
    np.testing.assert_array_equal(other.disparity, pair.disparity)


def test_the_baseline_is_the_rigs(scene: streaks.Scene) -> None:
    wide = scene.render_pair(**{**TINY, "spp": 1}, baseline=2 * streaks.DEFAULT_BASELINE)
    rig = wide.meta["rig"]
    assert rig["baseline"] == pytest.approx(2 * streaks.DEFAULT_BASELINE)
    assert wide.meta["settings"]["baseline"] == pytest.approx(2 * streaks.DEFAULT_BASELINE)
    # Each eye sits at -b/2 and +b/2 along the rig's +X.
    left, right = (np.array(rig[e]["position"]) for e in ("left", "right"))
    x_axis = np.array(rig["world_from_rig"]["x_axis"])
    np.testing.assert_allclose(right - left, 2 * streaks.DEFAULT_BASELINE * x_axis, atol=1e-6)
    hit = np.isfinite(wide.depth)
    f = rig["intrinsics"]["focal_px"]
    np.testing.assert_allclose(
        wide.disparity[hit], f * rig["baseline"] / wide.depth[hit], rtol=1e-6
    )


def test_render_gives_the_layers_of_the_exr(scene: streaks.Scene) -> None:
    view = scene.render(width=24, height=16, spp=1, threads=2)
    # The street has neither rain nor fog: no such layers, as in its EXR.
    assert set(view) == {"rgb", "depth", "normal", "albedo", "specular", "spp", "object"}
    assert view["rgb"].shape == (16, 24, 3) and view["depth"].shape == (16, 24)
    assert all(a.dtype == np.float32 for a in view.values())
    np.testing.assert_array_equal(view["spp"], np.ones((16, 24), np.float32))
    np.testing.assert_array_equal(
        view["rgb"], scene.render(width=24, height=16, spp=1, threads=1)["rgb"]
    )


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"spp": 0}, "spp must be at least 1"),
        ({"max_depth": 0}, "max_depth must be at least 1"),
        ({"noise_target": -1.0}, "noise_target must be a positive"),
        ({"baseline": 0.0}, "baseline must be a positive number of metres, got 0"),
        ({"exposure": float("nan")}, "exposure must be a finite number"),
        ({"shutter": -1.0}, "shutter must be a time of 0 s or more"),
        ({"width": 0}, "the image size must be positive, got a width of 0"),
        ({"camera": "nowhere"}, "rainy_street_small.gltf"),
        ({"camera": 7}, "rainy_street_small.gltf"),
        ({"sensor": "no_such_preset"}, "sensor"),
    ],
)
def test_bad_options_raise_a_streaks_error_naming_them(
    scene: streaks.Scene, options: dict[str, object], message: str
) -> None:
    with pytest.raises(streaks.StreaksError, match=message.replace(".", r"\.")):
        scene.render_pair(**{**TINY, **options})


def test_unknown_keywords_and_wrong_types_are_type_errors(scene: streaks.Scene) -> None:
    with pytest.raises(
        TypeError, match="render_pair\\(\\) got an unexpected keyword argument 'spps'"
    ):
        scene.render_pair(spps=2)  # type: ignore[call-arg]
    with pytest.raises(
        TypeError, match="render\\(\\) got an unexpected keyword argument 'baseline'"
    ):
        scene.render(baseline=0.5)  # type: ignore[call-arg]
    with pytest.raises(TypeError, match="^spp: "):
        scene.render_pair(spp="many")  # type: ignore[arg-type]


def test_bad_scenes_raise_a_streaks_error_naming_the_file(tmp_path: Path) -> None:
    assert issubclass(streaks.StreaksError, ValueError)
    missing = tmp_path / "missing.gltf"
    with pytest.raises(streaks.StreaksError, match=f"cannot load the scene {missing}"):
        streaks.Scene.load(missing)
    text = tmp_path / "scene.txt"
    text.write_text("not a scene")
    with pytest.raises(streaks.StreaksError, match="unsupported scene format"):
        streaks.Scene.load(text)
    broken = tmp_path / "broken.gltf"
    broken.write_text("{ not json")
    with pytest.raises(streaks.StreaksError, match="broken.gltf: invalid glTF"):
        streaks.Scene.load(broken)
    # A scene that names a file outside its folder is refused unless allowed.
    (tmp_path / "outside.bin").write_bytes(bytes(12))
    inner = tmp_path / "inner"
    inner.mkdir()
    escaping = inner / "escaping.gltf"
    escaping.write_text(
        json.dumps(
            {
                "asset": {"version": "2.0"},
                "buffers": [{"uri": "../outside.bin", "byteLength": 12}],
            }
        )
    )
    with pytest.raises(streaks.StreaksError, match="allow_outside_scene=True"):
        streaks.Scene.load(escaping)
    with pytest.raises(streaks.StreaksError, match="env_strength needs env or env_color"):
        streaks.Scene.load(SCENE, env_strength=2.0)


def test_a_scene_without_cameras_is_framed_with_a_warning(tmp_path: Path) -> None:
    empty = tmp_path / "empty.gltf"
    empty.write_text(
        json.dumps({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}], "scene": 0})
    )
    scene = streaks.Scene.load(empty, env_color=(0.5, 0.5, 0.5))
    assert scene.cameras == []
    with pytest.warns(UserWarning, match="scene has no camera"):
        view = scene.render(width=8, height=6, spp=1, max_depth=1)
    # A constant environment seen directly: every pixel is its radiance, depth inf.
    np.testing.assert_array_equal(view["rgb"], np.full((6, 8, 3), 0.5, np.float32))
    assert np.isinf(view["depth"]).all()


def test_a_pair_gives_the_training_arrays_a_sample_gives(pair: streaks.Pair) -> None:
    t = streaks.dataset.training_arrays(pair)
    np.testing.assert_array_equal(
        t["left"], pair.left_camera.transpose(2, 0, 1).astype(np.float32) / 255
    )
    np.testing.assert_array_equal(t["valid"], np.isfinite(pair.disparity))
    np.testing.assert_array_equal(t["noc"], t["valid"] & ~pair.occlusion)
    assert np.isfinite(t["disparity"]).all() and t["has_road"]
    assert t["id"] == "seed3"
