"""The `streaks-ray` command: `streaks-ray generate --address ADDR -o DIR --count N ...`."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from streaks.ray import __version__
from streaks.ray.driver import DriverError, Job, generate
from streaks.ray.plan import GenerateFlags, Shard, parse_shard

DESCRIPTION = """\
Run `streaks dataset generate` on a Ray cluster: the samples are split into Ray tasks of
--chunk samples (each one `streaks dataset generate ... --shard`), failed tasks are retried,
and `streaks dataset index --rebuild DIR` runs at the end. The dataset is the one `streaks dataset
generate` writes on one machine with the same flags, byte for byte.

On a real cluster the output folder (and --config, and the streaks binary) must be at the
same path on every node: DIR must be on a filesystem all nodes share (NFS, a parallel
filesystem); every node needs the same Python, Ray and streaks-ray as the driver."""


def _integer(minimum: int) -> Callable[[str], int]:
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"{value} is less than {minimum}")
        return value

    return parse


def _noise_target(text: str) -> str:
    """`--noise-target`: `off`, or a positive, finite number (passed on as written)."""
    if text == "off":
        return text
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is neither a number nor off") from None
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f"{text} is not a positive, finite number")
    return text


def _shard(text: str) -> Shard:
    try:
        return parse_shard(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def parser() -> argparse.ArgumentParser:
    """The command's argument parser."""
    top = argparse.ArgumentParser(
        prog="streaks-ray", description="Generate streaks datasets on a Ray cluster."
    )
    top.add_argument("--version", action="version", version=f"streaks-ray {__version__}")
    commands = top.add_subparsers(dest="command", required=True, metavar="COMMAND")
    gen = commands.add_parser(
        "generate",
        help="run `streaks dataset generate` in Ray tasks",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ray_group = gen.add_argument_group("Ray")
    ray_group.add_argument(
        "--address",
        required=True,
        metavar="ADDR",
        help="the Ray cluster: host:port of its head (as `ray start --head` prints), "
        "ray://host:port, or auto",
    )
    ray_group.add_argument(
        "--streaks-bin",
        default="streaks",
        metavar="PATH",
        help="the streaks binary, at the same path on every node (default: streaks on PATH)",
    )
    ray_group.add_argument(
        "--num-cpus",
        type=_integer(1),
        default=1,
        metavar="C",
        help="Ray CPUs per task; the renderer runs with --threads C (default 1)",
    )
    ray_group.add_argument(
        "--chunk", type=_integer(1), default=1, metavar="M", help="samples per task (default 1)"
    )
    ray_group.add_argument(
        "--max-retries",
        type=_integer(0),
        default=3,
        metavar="R",
        help="run a failed task again up to R times (default 3)",
    )
    flags = gen.add_argument_group("streaks dataset generate (passed to every task)")
    flags.add_argument(
        "-o",
        dest="out",
        required=True,
        type=Path,
        metavar="DIR",
        help="the dataset folder; on a cluster, on a filesystem every node shares",
    )
    flags.add_argument(
        "--count", type=_integer(1), required=True, metavar="N", help="samples in the dataset"
    )
    flags.add_argument("--seed", type=_integer(0), metavar="S", help="the dataset's seed")
    flags.add_argument(
        "--config",
        type=Path,
        metavar="FILE",
        help="the generator config (TOML); on a cluster, on a filesystem every node shares",
    )
    flags.add_argument("--width", type=_integer(1), metavar="W", help="image width")
    flags.add_argument("--height", type=_integer(1), metavar="H", help="image height")
    flags.add_argument("--spp", type=_integer(1), metavar="P", help="samples per pixel")
    flags.add_argument("--max-depth", type=_integer(1), metavar="D", help="path depth")
    flags.add_argument(
        "--noise-target",
        type=_noise_target,
        metavar="REL|off",
        help="adaptive sampling's target relative error, --spp the cap; off: fixed --spp",
    )
    flags.add_argument(
        "--no-regularize", action="store_true", help="render without path regularisation"
    )
    flags.add_argument(
        "--denoise",
        choices=["auto", "on", "off"],
        help="denoise the images with Intel Open Image Denoise (default auto: when installed; "
        "on a cluster give on or off, so that every node denoises alike)",
    )
    flags.add_argument(
        "--keep-raw", action="store_true", help="keep the render before denoising in each EXR"
    )
    flags.add_argument(
        "--outputs",
        metavar="GROUPS",
        help="the groups of files each sample keeps, comma-separated (images, images16, exr, "
        "gt, masks, segmentation, flow, scene, kitti, sceneflow; default all but images16), as "
        "for `streaks dataset generate`",
    )
    flags.add_argument(
        "--shard",
        type=_shard,
        default=Shard(0, 1),
        metavar="K/N",
        help="only the samples i with i = K mod N, split again among the tasks; like "
        "`streaks dataset generate --shard`, writes no manifest (index once all shards are done)",
    )
    return top


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command; returns the exit status."""
    args = parser().parse_args(argv)
    job = Job(
        address=args.address,
        streaks_bin=args.streaks_bin,
        flags=GenerateFlags(
            out=args.out,
            count=args.count,
            seed=args.seed,
            config=args.config,
            width=args.width,
            height=args.height,
            spp=args.spp,
            max_depth=args.max_depth,
            noise_target=args.noise_target,
            no_regularize=args.no_regularize,
            denoise=args.denoise,
            keep_raw=args.keep_raw,
            outputs=args.outputs,
        ),
        shard=args.shard,
        num_cpus=args.num_cpus,
        chunk=args.chunk,
        max_retries=args.max_retries,
    )
    try:
        return generate(job)
    except DriverError as err:
        print(f"streaks-ray: error: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(
            "streaks-ray: interrupted; the tasks were cancelled, the samples published so far "
            "are kept: run the same command again to resume",
            file=sys.stderr,
        )
        return 130
