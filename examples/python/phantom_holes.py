"""Do specular streaks fool your stereo method? Render pairs in-process, load them with a
PyTorch DataLoader and score disparity methods against the exact ground truth.

    pip install './python[torch]'      # the package in release, with PyTorch
    python examples/python/phantom_holes.py

renders a few stereo pairs of the shipped rainy street (each with its own seed and baseline),
wraps them in a `torch.utils.data.Dataset`, and for every batch of the `DataLoader` runs

- `sgm` and `sgm-streaks`: the project's semi-global matching, plain and with its streak
  repair (`streaks.disparity`, as `streaks benchmark` runs them);
- `block-matching`: a batched sum-of-absolute-differences matcher written in PyTorch, in the
  place where your network would go;

then scores each map with `streaks.score` (as `streaks benchmark` does). The figure to watch
is the phantom-hole rate: the share of the road that a method puts more than 1 px below the
true disparity, where a driver-assistance system would see a hole that is not there. The
streak pixels are where it happens.

Without PyTorch the pairs are scored one by one and `block-matching` is left out. The whole
run takes about a minute at the defaults on two cores (release build).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

import numpy as np
import streaks

ROOT = Path(__file__).resolve().parents[2]


def block_matching(left: Any, right: Any, max_disparity: int = 64, radius: int = 4) -> Any:
    """Winner-takes-all disparity of a batch (B x 3 x H x W tensors in [0, 1]): the mean
    absolute difference of grey values over (2 radius + 1)^2 windows, for every shift from 0 to
    `max_disparity - 1`; 0 (no value) where the shift leaves the right image."""
    import torch
    import torch.nn.functional as F

    weights = torch.tensor([0.2127, 0.7152, 0.0722]).view(1, 3, 1, 1)
    gl, gr = (left * weights).sum(1, keepdim=True), (right * weights).sum(1, keepdim=True)
    b, _, h, w = gl.shape
    costs = torch.full((b, max_disparity, h, w), float("inf"))
    for d in range(max_disparity):
        diff = (gl[..., d:] - gr[..., : w - d]).abs()
        box = F.avg_pool2d(diff, 2 * radius + 1, stride=1, padding=radius, count_include_pad=False)
        costs[:, d, :, d:] = box[:, 0]
    best = costs.argmin(1).float()
    best[torch.isinf(costs.min(1).values)] = 0.0
    return best


def score(estimate: np.ndarray, item: dict[str, Any]) -> dict[str, Any]:
    """The benchmark's scores of `estimate` for one item of the training arrays."""
    truth = np.where(item["valid"], item["disparity"], np.inf).astype(np.float32)
    road = item["road_mask"] if item["has_road"] else None
    return streaks.score(
        estimate.astype(np.float32),
        truth,
        streak_mask=item["streak_mask"],
        road_mask=road,
        occlusion=item["valid"] & ~item["noc"],
    )


def summary(name: str, scores: list[dict[str, Any]], seconds: float, pixels: int) -> str:
    """One table row: the scores pooled over the pairs, pixel-weighted as the benchmark pools."""

    def pooled(region: str, key: str, weight: str) -> float:
        parts = [(s[region][key], s[region][weight]) for s in scores if s[region] is not None]
        total = sum(w for _, w in parts)
        return sum(v * w for v, w in parts) / total if total else float("nan")

    epe = pooled("all", "mean_abs", "valid_pixels")
    bad2 = pooled("all", "bad_2", "valid_pixels")
    streak_epe = pooled("streak", "mean_abs", "valid_pixels")
    holes = pooled("road_surface", "below_1px", "truth_pixels")
    return (
        f"{name:<15} {epe:8.3f} {100 * bad2:7.1f} % {streak_epe:11.3f}"
        f" {100 * holes:14.1f} % {seconds / pixels * 1e6:9.2f}"
    )


def main(argv: list[str] | None = None) -> int:
    """Render, load, estimate and score; prints the table and returns 0."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scene", type=Path, default=ROOT / "scenes" / "rainy_street_small.gltf")
    p.add_argument("--pairs", type=int, default=4, help="how many pairs to render")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--height", type=int, default=192)
    p.add_argument("--spp", type=int, default=16, help="samples per pixel per eye")
    p.add_argument("--batch-size", type=int, default=2)
    p.add_argument("--no-torch", action="store_true", help="score without PyTorch")
    args = p.parse_args(argv)

    scene = streaks.Scene.load(args.scene)
    baselines = [0.12, 0.2, 0.3, 0.4]
    pairs = []
    start = time.perf_counter()
    for i in range(args.pairs):
        pairs.append(
            scene.render_pair(
                width=args.width,
                height=args.height,
                spp=args.spp,
                seed=2 * i,
                baseline=baselines[i % len(baselines)],
            )
        )
        print(f"rendered pair {i + 1}/{args.pairs}: {pairs[-1]}", flush=True)
    render_s = time.perf_counter() - start
    print(f"{args.pairs} pairs in {render_s:.1f} s ({render_s / args.pairs:.2f} s per pair)")

    # Everything a loss would see: images in [0, 1], disparity 0 where there is none, masks.
    items = [streaks.dataset.training_arrays(pair) for pair in pairs]

    methods: dict[str, list[dict[str, Any]]] = {"sgm": [], "sgm-streaks": []}
    seconds = dict.fromkeys(["sgm", "sgm-streaks", "block-matching"], 0.0)

    def builtin(item: dict[str, Any]) -> None:
        left, right = item["left"].transpose(1, 2, 0), item["right"].transpose(1, 2, 0)
        for name in ("sgm", "sgm-streaks"):
            t0 = time.perf_counter()
            estimate = streaks.disparity(left, right, method=name)
            seconds[name] += time.perf_counter() - t0
            methods[name].append(score(estimate, item))

    torch_ok = not args.no_torch
    if torch_ok:
        try:
            import torch
            from torch.utils.data import DataLoader, Dataset
        except ImportError:
            print("PyTorch is not installed (pip install torch): scoring without it")
            torch_ok = False
    if torch_ok:

        class Pairs(Dataset):  # type: ignore[type-arg]
            """The rendered pairs as tensors (what `streaks.torch.StereoDataset` gives for a
            dataset on disk)."""

            def __len__(self) -> int:
                return len(items)

            def __getitem__(self, i: int) -> dict[str, Any]:
                return {
                    k: torch.from_numpy(v) if isinstance(v, np.ndarray) else v
                    for k, v in items[i].items()
                }

        methods["block-matching"] = []
        for batch in DataLoader(Pairs(), batch_size=args.batch_size):
            t0 = time.perf_counter()
            estimates = block_matching(batch["left"], batch["right"])
            seconds["block-matching"] += time.perf_counter() - t0
            for j in range(estimates.shape[0]):
                item = {
                    k: v[j].numpy() if hasattr(v[j], "numpy") else v[j] for k, v in batch.items()
                }
                methods["block-matching"].append(score(estimates[j].numpy(), item))
                builtin(item)
    else:
        for item in items:
            builtin(item)

    pixels = sum(item["disparity"].size for item in items)
    print()
    print(
        f"{'method':<15} {'EPE px':>8} {'bad-2':>9} {'streak EPE':>11} {'phantom holes':>16}"
        f" {'s / MP':>9}"
    )
    for name, scores in methods.items():
        print(summary(name, scores, seconds[name], pixels))
    print(
        "\nphantom holes: road pixels put more than 1 px below the true disparity "
        "(streaks.score's phantom_hole_rate); bad-2 over all pixels with a value"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
