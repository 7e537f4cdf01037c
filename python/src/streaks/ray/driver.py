"""The driver: checks, connects to Ray, runs one task per chunk, retries, indexes.

Retries are the driver's, not Ray's: each task is submitted with `max_retries=0`, and when
one fails (the renderer exits non-zero, is killed, or the Ray worker dies) the driver says so
on stderr and submits the chunk again, up to `--max-retries` times. A chunk that is run again
renders only what is missing: `streaks dataset generate` skips published samples and cleans
the temporary folder the failed run left.
"""

from __future__ import annotations

import ipaddress
import logging
import os
import shutil
import socket
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tqdm import tqdm

from streaks.ray.plan import WHOLE, Chunk, GenerateFlags, Shard, plan_chunks, sample_folder
from streaks.ray.task import RunResult, run_renderer

POLL_SECONDS = 0.5
"""How often the progress bar counts the published samples."""
SHOWN_FAILURES = 5
"""How many failed chunks the final report shows with the renderer's output."""
CONNECT_TIMEOUT_SECONDS = 10.0
"""How long the check that something listens at the Ray address waits."""


class DriverError(Exception):
    """A problem the driver reports as `streaks-ray: error: ...` and exits non-zero for."""


@dataclass(frozen=True)
class Job:
    """Everything `streaks-ray generate` was asked to do."""

    address: str
    """The Ray cluster's address (`host:port`, `ray://host:port` or `auto`)."""
    streaks_bin: str
    """The streaks binary as given (a path, or a name looked up on PATH)."""
    flags: GenerateFlags
    """The flags every task passes to `streaks dataset generate`."""
    shard: Shard = WHOLE
    """The user's `--shard`: the driver renders only these samples."""
    num_cpus: int = 1
    """Ray CPUs per task, and the renderer's `--threads`."""
    chunk: int = 1
    """Samples per task, at most."""
    max_retries: int = 3
    """How many times a failed chunk is run again."""


@dataclass
class _Progress:
    """The published samples of the job, counted on the shared filesystem."""

    samples_dir: Path
    wanted: frozenset[str]
    bar: tqdm[Any] = field(init=False)
    done: int = field(init=False, default=0)
    at_start: int = field(init=False, default=0)

    def __post_init__(self) -> None:
        self.at_start = self.done = self.count()
        disabled = os.environ.get("CI") == "true" or not sys.stderr.isatty()
        self.bar = tqdm(
            total=len(self.wanted),
            initial=self.done,
            unit="pair",
            desc="streaks-ray",
            file=sys.stderr,
            disable=disabled,
            dynamic_ncols=True,
        )

    def count(self) -> int:
        try:
            names = os.listdir(self.samples_dir)
        except FileNotFoundError:
            return 0
        return len(self.wanted.intersection(names))

    def update(self) -> None:
        now = self.count()
        if now != self.done:
            self.bar.update(now - self.done)
            self.done = now

    def say(self, message: str) -> None:
        """Print a line on stderr without breaking the bar."""
        self.bar.write(message, file=sys.stderr)


def resolve_binary(name: str) -> str:
    """The absolute path of the streaks binary, checked to run and to have `dataset generate`."""
    found = shutil.which(name) if os.sep not in name else name
    if found is None or not os.path.isfile(found):
        where = "on PATH" if os.sep not in name else "at that path"
        raise DriverError(f"streaks binary '{name}' not found {where} (give --streaks-bin PATH)")
    path = os.path.abspath(found)
    for args, what in (
        (["--version"], "--version"),
        (["dataset", "generate", "--help"], "dataset generate --help"),
    ):
        try:
            proc = subprocess.run(
                [path, *args], capture_output=True, text=True, timeout=60, check=False
            )
        except (OSError, subprocess.TimeoutExpired) as err:
            raise DriverError(f"cannot run the streaks binary {path}: {err}") from None
        if proc.returncode != 0:
            said = (proc.stderr.strip().splitlines() or [""])[0]
            raise DriverError(
                f"{path} {what} exited with status {proc.returncode}"
                + (f": {said}" if said else "")
                + " (is it a streaks binary with the `dataset` command?)"
            )
    return path


def check_output_folder(out: Path) -> Path:
    """The dataset folder made absolute; it or its parent must be an existing folder."""
    out = Path(os.path.abspath(out.expanduser()))
    if out.exists() and not out.is_dir():
        raise DriverError(f"output {out} exists and is not a folder")
    if not out.exists() and not out.parent.is_dir():
        raise DriverError(f"output {out}: its parent folder {out.parent} does not exist")
    return out


def check_config(config: Path | None) -> Path | None:
    """The config file made absolute, checked to be a readable file."""
    if config is None:
        return None
    config = Path(os.path.abspath(config.expanduser()))
    if not config.is_file():
        raise DriverError(f"config {config} is not a file")
    try:
        with config.open("rb"):
            pass
    except OSError as err:
        raise DriverError(f"config {config} cannot be read: {err.strerror}") from None
    return config


def _host_port(address: str) -> tuple[str, int] | None:
    """The host and port of `host:port` or `ray://host:port`; None for `auto` and the like."""
    rest = address.removeprefix("ray://")
    host, colon, port = rest.rpartition(":")
    if not colon or not port.isdigit():
        return None
    return host.strip("[]"), int(port)


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def connect(address: str) -> None:
    """Connect to the Ray cluster at `address`, with a clear error when there is none.

    Ray's own connection attempt waits minutes for a cluster that is not there, so a plain
    TCP connection is tried first. For a loopback address Ray is told to stay on loopback
    (`RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0`): otherwise it replaces 127.0.0.1 with the
    machine's network address.
    """
    parsed = _host_port(address)
    if parsed is not None:
        host, port = parsed
        try:
            with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_SECONDS):
                pass
        except OSError as err:
            raise DriverError(
                f"no Ray cluster at {address}: cannot connect to {host}:{port} "
                f"({err.strerror or err}); start one with `ray start --head` or give its address"
            ) from None
        if _is_loopback(host):
            os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
    import ray

    try:
        ray.init(address=address, logging_level=logging.WARNING, log_to_driver=False)
    except (ConnectionError, RuntimeError, ValueError) as err:
        raise DriverError(f"cannot connect to the Ray cluster at {address}: {err}") from None


def _cluster_cpus(num_cpus: int) -> tuple[int, float]:
    """The number of live nodes and of CPUs; fails if no node has `num_cpus` CPUs."""
    import ray

    nodes = [n for n in ray.nodes() if n.get("Alive")]
    largest = max((n.get("Resources", {}).get("CPU", 0.0) for n in nodes), default=0.0)
    if largest < num_cpus:
        raise DriverError(
            f"no node of the Ray cluster has {num_cpus} CPUs (the largest has {largest:g}): "
            "a task would wait forever; lower --num-cpus"
        )
    return len(nodes), float(ray.cluster_resources().get("CPU", 0.0))


def _run_chunk(binary: str, args: list[str], out: str) -> RunResult:
    """The Ray task: run the renderer for one chunk."""
    return run_renderer(binary, args, Path(out))


def _ray_failure(err: BaseException) -> str:
    first = (str(err).strip().splitlines() or [""])[0]
    return f"Ray task failed: {type(err).__name__}: {first}"


@dataclass
class _Attempt:
    chunk: Chunk
    number: int


def _run_chunks(
    job: Job, binary: str, chunks: list[Chunk], progress: _Progress
) -> tuple[int, list[tuple[Chunk, str, str]]]:
    """Run every chunk to success or until its retries are spent.

    Returns the number of retries and, for each chunk that failed every attempt, the chunk,
    the last reason and the renderer's last stderr lines.
    """
    import ray

    remote = ray.remote(_run_chunk).options(num_cpus=job.num_cpus, max_retries=0)
    out = str(job.flags.out)
    attempts = job.max_retries + 1

    def submit(chunk: Chunk, number: int) -> tuple[Any, _Attempt]:
        args = job.flags.arguments(chunk.shard, job.num_cpus)
        return remote.remote(binary, args, out), _Attempt(chunk, number)

    pending = dict(submit(chunk, 1) for chunk in chunks)
    retries = 0
    failed: list[tuple[Chunk, str, str]] = []
    try:
        while pending:
            # Every task that is done within the poll interval (one at a time would make a
            # dataset of n tasks cost n^2).
            refs = list(pending)
            ready, _ = ray.wait(refs, num_returns=len(refs), timeout=POLL_SECONDS)
            progress.update()
            for ref in ready:
                attempt = pending.pop(ref)
                stderr_tail = ""
                try:
                    result: RunResult = ray.get(ref)
                except ray.exceptions.RayError as err:
                    reason = _ray_failure(err)
                else:
                    if result.ok:
                        continue
                    reason, stderr_tail = result.reason(), result.stderr_tail
                what = f"{attempt.chunk.describe()} failed: {reason}"
                if attempt.number < attempts:
                    retries += 1
                    progress.say(
                        f"streaks-ray: {what}; retrying, attempt {attempt.number + 1} of {attempts}"
                    )
                    ref, again = submit(attempt.chunk, attempt.number + 1)
                    pending[ref] = again
                else:
                    progress.say(f"streaks-ray: {what}; giving up after {attempts} attempts")
                    failed.append((attempt.chunk, reason, stderr_tail))
    except KeyboardInterrupt:
        for ref in pending:
            ray.cancel(ref)
        raise
    progress.update()
    return retries, failed


def generate(job: Job) -> int:
    """Run the job; returns the exit status (`streaks dataset index --rebuild`'s on success)."""
    started = time.monotonic()
    binary = resolve_binary(job.streaks_bin)
    flags = GenerateFlags(
        out=check_output_folder(job.flags.out),
        count=job.flags.count,
        seed=job.flags.seed,
        config=check_config(job.flags.config),
        width=job.flags.width,
        height=job.flags.height,
        spp=job.flags.spp,
        max_depth=job.flags.max_depth,
        noise_target=job.flags.noise_target,
        no_regularize=job.flags.no_regularize,
        denoise=job.flags.denoise,
        keep_raw=job.flags.keep_raw,
        outputs=job.flags.outputs,
    )
    job = Job(job.address, binary, flags, job.shard, job.num_cpus, job.chunk, job.max_retries)
    chunks = plan_chunks(flags.count, job.shard, job.chunk)
    if not chunks:
        raise DriverError(
            f"--shard {job.shard} selects no sample of --count {flags.count} "
            f"(the first sample of that shard would be {job.shard.index})"
        )
    connect(job.address)
    nodes, cpus = _cluster_cpus(job.num_cpus)
    wanted = frozenset(sample_folder(i) for c in chunks for i in c.samples)
    print(
        f"streaks-ray: {len(wanted)} samples in {len(chunks)} tasks of at most {job.chunk}, "
        f"{job.num_cpus} CPU each, on {nodes} node(s) with {cpus:g} CPUs; into {flags.out}",
        file=sys.stderr,
    )
    progress = _Progress(flags.out / "samples", wanted)
    try:
        retries, failed = _run_chunks(job, binary, chunks, progress)
    finally:
        progress.bar.close()
    wall = time.monotonic() - started
    rendered = progress.done - progress.at_start
    pairs_per_hour = rendered / wall * 3600 if wall > 0 else 0.0
    summary = (
        f"{progress.done} of {len(wanted)} samples ({rendered} rendered now, "
        f"{progress.at_start} already there) in {len(chunks)} tasks, "
        f"{retries} {'retry' if retries == 1 else 'retries'}, {len(failed)} failed, "
        f"{wall:.1f} s wall, {pairs_per_hour:.0f} pairs/hour"
    )
    if failed:
        for chunk, reason, stderr_tail in failed[:SHOWN_FAILURES]:
            print(f"streaks-ray: {chunk.describe()}: {reason}", file=sys.stderr)
            for line in stderr_tail.splitlines():
                print(f"    {line}", file=sys.stderr)
        if len(failed) > SHOWN_FAILURES:
            print(
                f"streaks-ray: and {len(failed) - SHOWN_FAILURES} more failed chunk(s)",
                file=sys.stderr,
            )
        print(f"streaks-ray: {summary}", file=sys.stderr)
        raise DriverError(
            f"{len(failed)} chunk(s) failed {job.max_retries + 1} times; the samples published so "
            "far are kept: run the same command again to render the rest"
        )
    if job.shard != WHOLE:
        # As `streaks dataset generate --shard`: a shard writes no manifest; index the
        # dataset once every shard is done.
        print(f"streaks-ray: {summary}; shard {job.shard} done (not indexed)")
        return 0
    # The driver wrote the samples, so it writes the manifest (as `generate` without --shard
    # does); `index` alone would verify against an older manifest.
    index = subprocess.run([binary, "dataset", "index", "--rebuild", str(flags.out)], check=False)
    status = "ok" if index.returncode == 0 else f"failed with status {index.returncode}"
    print(f"streaks-ray: {summary}; index {status}")
    return index.returncode
