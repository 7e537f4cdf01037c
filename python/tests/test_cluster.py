"""streaks-ray on a real local Ray cluster (127.0.0.1 only): the dataset equals, file for file,
the one `streaks dataset generate` writes on one machine; a renderer killed mid-render is
retried; shards and resuming; a renderer that keeps failing."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import time
from pathlib import Path

from conftest import (
    TINY,
    RayCluster,
    assert_ray_listens_on_loopback_only,
    assert_same_dataset,
    cmdline_of,
    ray_env,
    streaks_ray,
)

TIMEOUT = 180


def _generate(cluster: RayCluster, streaks_bin: str, out: Path, *flags: str) -> list[str]:
    return streaks_ray(
        "generate", "--address", cluster.address, "--streaks-bin", streaks_bin, "-o", str(out)
    ) + list(flags)


def _run(command: list[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        command, env=ray_env(), capture_output=True, text=True, timeout=TIMEOUT, check=False
    )


def test_the_dataset_equals_the_single_machine_one(ray_cluster, streaks_bin, reference, tmp_path):
    out = tmp_path / "dataset"
    run = _run(_generate(ray_cluster, streaks_bin, out, *TINY))
    assert run.returncode == 0, run.stderr
    assert "4 samples in 4 tasks of at most 1, 1 CPU each, on 1 node(s)" in run.stderr
    assert re.search(
        r"4 of 4 samples \(4 rendered now, 0 already there\) in 4 tasks, 0 retries", run.stdout
    )
    assert "index ok" in run.stdout
    assert_same_dataset(out, reference)


def _renderers(streaks_bin: str, out: Path) -> list[int]:
    """The `streaks dataset generate -o out` processes now running."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            args = cmdline_of(int(entry.name))
            if args[:3] == [streaks_bin, "dataset", "generate"] and str(out) in args:
                found.append(int(entry.name))
    return found


def _rendering(out: Path, pid: int) -> bool:
    """Renderer `pid` is in the middle of a sample: its temporary sample folder exists
    (`samples/.tmp-NNNNNN-PID/`, published by a rename when the sample is complete)."""
    return any((out / "samples").glob(f".tmp-*-{pid}"))


def test_a_killed_renderer_is_retried(ray_cluster, streaks_bin, reference, tmp_path):
    out = tmp_path / "dataset"
    driver = subprocess.Popen(
        _generate(ray_cluster, streaks_bin, out, *TINY, "--chunk", "2"),
        env=ray_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        # Find a renderer in the middle of a sample (its temporary folder exists), kill it.
        deadline = time.monotonic() + 60
        victim = None
        while victim is None and time.monotonic() < deadline and driver.poll() is None:
            busy = [pid for pid in _renderers(streaks_bin, out) if _rendering(out, pid)]
            if busy:
                victim = busy[0]
            else:
                time.sleep(0.01)
        assert victim is not None, "saw no renderer in the middle of a sample"
        shard = cmdline_of(victim)[cmdline_of(victim).index("--shard") + 1]
        os.kill(victim, signal.SIGKILL)
        stdout, stderr = driver.communicate(timeout=TIMEOUT)
    finally:
        if driver.poll() is None:
            driver.kill()
            driver.communicate()
    assert driver.returncode == 0, stderr
    chunk = int(shard.split("/")[0])
    assert shard.endswith("/2")  # two chunks of two samples
    samples = f"samples {chunk}, {chunk + 2}"
    retried = f"chunk {chunk} ({samples}) failed: renderer killed by signal 9 (SIGKILL) on "
    assert retried in stderr and "; retrying, attempt 2 of 4" in stderr, stderr
    assert re.search(r"4 of 4 samples .* in 2 tasks, 1 retry, 0 failed", stdout), stdout
    assert "index ok" in stdout
    assert_same_dataset(out, reference)
    # The workers that ran the tasks are still up: every socket of the cluster is on loopback.
    assert_ray_listens_on_loopback_only(ray_cluster)


def test_shards_then_resume_give_the_same_dataset(ray_cluster, streaks_bin, reference, tmp_path):
    out = tmp_path / "dataset"
    shard = _run(_generate(ray_cluster, streaks_bin, out, *TINY, "--shard", "1/2"))
    assert shard.returncode == 0, shard.stderr
    assert "2 samples in 2 tasks" in shard.stderr and "shard 1/2 done (not indexed)" in shard.stdout
    samples = sorted(p.name for p in (out / "samples").iterdir())
    assert samples == ["000001", "000003"]
    assert not (out / "manifest.jsonl").exists()
    # The whole dataset: the shard's samples are skipped, the others rendered, then indexed.
    rest = _run(_generate(ray_cluster, streaks_bin, out, *TINY, "--chunk", "4"))
    assert rest.returncode == 0, rest.stderr
    assert "4 of 4 samples (2 rendered now, 2 already there) in 1 tasks" in rest.stdout
    assert_same_dataset(out, reference)


def test_a_renderer_that_keeps_failing_is_given_up(ray_cluster, streaks_bin, tmp_path):
    config = tmp_path / "bad.toml"
    config.write_text("no_such_key = 1\n")
    out = tmp_path / "dataset"
    run = _run(
        _generate(ray_cluster, streaks_bin, out, *TINY, "--config", str(config))
        + ["--chunk", "4", "--max-retries", "1"]
    )
    assert run.returncode == 1
    assert "chunk 0 (samples 0, 1, 2, 3) failed: renderer exited with status" in run.stderr
    assert "; retrying, attempt 2 of 2" in run.stderr
    assert "; giving up after 2 attempts" in run.stderr
    assert "no_such_key" in run.stderr  # the renderer's own message is shown
    assert "streaks-ray: error: 1 chunk(s) failed 2 times" in run.stderr
    assert "index" not in run.stdout
