"""Fixtures: the streaks binary (environment variable STREAKS), a real local Ray cluster bound to
loopback, and the dataset `streaks dataset generate` writes on one machine.

Every Ray address in these tests is 127.0.0.1: the cluster is started with
`--node-ip-address 127.0.0.1` and RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0 (without it Ray replaces
127.0.0.1 with the machine's network address), and the fixture asserts that every node's
address is 127.0.0.1.
"""

from __future__ import annotations

import ipaddress
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

BIN = Path(sys.executable).parent
"""The environment's scripts folder (ray, streaks-ray)."""

TINY = ["--count", "4", "--seed", "7", "--width", "64", "--height", "40", "--spp", "2"]
"""The dataset flags of the cluster tests: four small samples, quick with a debug binary."""


def ray_env() -> dict[str, str]:
    """The environment for Ray and the driver: loopback only, no usage stats, no CI bar."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
    env["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
    env["RAY_USAGE_STATS_ENABLED"] = "0"
    return env


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nothing listens on (at the time of asking)."""
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _executable(name: str) -> str:
    path = BIN / name
    if path.exists():
        return str(path)
    found = shutil.which(name)
    assert found, f"{name} is not installed in this environment (pip install ./python)"
    return found


@pytest.fixture(scope="session")
def streaks_bin() -> str:
    """The streaks binary, from STREAKS (CI sets it to target/debug/streaks)."""
    path = os.environ.get("STREAKS")
    if not path:
        pytest.skip(
            "STREAKS is not set: build the binary (cargo build --bin streaks) and run with "
            "STREAKS=target/debug/streaks"
        )
    path = os.path.abspath(path)
    assert os.path.isfile(path), f"STREAKS={path} is not a file"
    return path


def generate(
    streaks_bin: str,
    root: Path,
    *,
    count: int,
    seed: int,
    size: tuple[int, int],
    spp: int = 1,
    extra: tuple[str, ...] = (),
) -> Path:
    """A tiny dataset in `root`, as `streaks dataset generate` writes it on one machine (two
    threads; `size` is width, height; `extra`: more flags). Returns `root`."""
    subprocess.run(
        [streaks_bin, "dataset", "generate", "-o", str(root), "--count", str(count)]
        + ["--seed", str(seed), "--width", str(size[0]), "--height", str(size[1])]
        + ["--spp", str(spp), "--threads", "2", *extra],
        check=True,
        capture_output=True,
        timeout=300,
    )
    return root


@dataclass(frozen=True)
class RayCluster:
    """A running local Ray cluster."""

    address: str
    temp_dir: Path


def _node_addresses(address: str) -> list[str]:
    code = (
        "import json, ray\n"
        f"ray.init(address={address!r}, logging_level='ERROR', log_to_driver=False)\n"
        "print(json.dumps([n['NodeManagerAddress'] for n in ray.nodes()]))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        env=ray_env(),
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return list(json.loads(out.stdout.strip().splitlines()[-1]))


@pytest.fixture(scope="session")
def ray_cluster() -> Iterator[RayCluster]:
    """A real Ray cluster of one node with 2 CPUs on 127.0.0.1, stopped at the end."""
    ray = _executable("ray")
    port = free_port()
    # Short: Ray puts its unix sockets under the temp folder (at most 107 characters).
    temp_dir = Path(tempfile.mkdtemp(prefix="streaks-ray-", dir="/tmp"))
    start = [
        ray, "start", "--head",
        "--node-ip-address", "127.0.0.1",
        "--port", str(port),
        "--num-cpus", "2",
        "--object-store-memory", str(100 * 1024 * 1024),
        "--disable-usage-stats",
        "--include-dashboard=false",
        "--temp-dir", str(temp_dir),
    ]  # fmt: skip
    try:
        started = subprocess.run(
            start, env=ray_env(), capture_output=True, text=True, timeout=180, check=False
        )
        assert started.returncode == 0, f"ray start failed:\n{started.stdout}\n{started.stderr}"
        address = f"127.0.0.1:{port}"
        nodes = _node_addresses(address)
        assert nodes and all(node == "127.0.0.1" for node in nodes), nodes
        yield RayCluster(address, temp_dir)
    finally:
        subprocess.run(
            [ray, "stop", "--force"], env=ray_env(), capture_output=True, timeout=180, check=False
        )
        shutil.rmtree(temp_dir, ignore_errors=True)


def _decode(hex_address: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address:
    """An address of /proc/net/tcp{,6}: little-endian 32-bit words in hex."""
    words = [bytes.fromhex(hex_address[i : i + 8])[::-1] for i in range(0, len(hex_address), 8)]
    raw = b"".join(words)
    return ipaddress.ip_address(raw)


def _is_loopback(address: ipaddress.IPv4Address | ipaddress.IPv6Address) -> bool:
    if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped is not None:
        return address.ipv4_mapped.is_loopback
    return address.is_loopback


def ray_listening_addresses(cluster: RayCluster) -> dict[int, list[str]]:
    """The addresses every TCP socket of the cluster's processes listens on, by process id.

    The cluster's processes are those whose command line names its temp folder, and their
    descendants (the workers, whose command lines Ray rewrites).
    """
    parents: dict[int, int] = {}
    cmdlines: dict[int, str] = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdlines[int(entry.name)] = (entry / "cmdline").read_bytes().decode(errors="replace")
        except OSError:
            continue
        parents[int(entry.name)] = int(stat.rpartition(")")[2].split()[1])
    family = {pid for pid, cmd in cmdlines.items() if str(cluster.temp_dir) in cmd}
    grew = True
    while grew:
        more = {pid for pid, parent in parents.items() if parent in family} - family
        family |= more
        grew = bool(more)
    listening: dict[str, str] = {}
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == "0A":  # LISTEN
                host, _, port = fields[1].partition(":")
                listening[fields[9]] = f"{_decode(host)}:{int(port, 16)}"
    found: dict[int, list[str]] = {}
    for pid in family:
        try:
            links = [os.readlink(fd) for fd in Path(f"/proc/{pid}/fd").iterdir()]
        except OSError:
            continue
        inodes = [link[8:-1] for link in links if link.startswith("socket:[")]
        addresses = [listening[i] for i in inodes if i in listening]
        if addresses:
            found[pid] = addresses
    return found


def assert_ray_listens_on_loopback_only(cluster: RayCluster) -> None:
    """Fail unless the cluster listens, and only on loopback addresses."""
    found = ray_listening_addresses(cluster)
    assert found, "found no listening socket of the Ray cluster"
    for pid, addresses in found.items():
        for address in addresses:
            host = address.rpartition(":")[0]
            assert _is_loopback(ipaddress.ip_address(host)), (pid, cmdline_of(pid), address)


def cmdline_of(pid: int) -> list[str]:
    """A process's arguments ([] if it is gone)."""
    try:
        raw = Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return []
    return [part.decode(errors="replace") for part in raw.split(b"\0") if part]


def files_of(folder: Path) -> dict[str, bytes]:
    """Every file under `folder`, by path relative to it, with its bytes."""
    return {
        str(path.relative_to(folder)): path.read_bytes()
        for path in sorted(folder.rglob("*"))
        if path.is_file()
    }


def assert_same_dataset(got: Path, want: Path) -> None:
    """The two folders hold the same files with the same bytes."""
    got_files, want_files = files_of(got), files_of(want)
    assert sorted(got_files) == sorted(want_files)
    differ = [name for name in want_files if got_files[name] != want_files[name]]
    assert not differ, f"files that differ from the single-machine dataset: {differ}"


@pytest.fixture(scope="session")
def reference(streaks_bin: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The dataset `streaks dataset generate` writes on one machine with the TINY flags."""
    out = tmp_path_factory.mktemp("reference") / "dataset"
    subprocess.run(
        [streaks_bin, "dataset", "generate", "-o", str(out), *TINY],
        check=True,
        capture_output=True,
        timeout=300,
    )
    assert (out / "manifest.jsonl").is_file()
    return out


def streaks_ray(*args: str) -> list[str]:
    """The command line of the installed `streaks-ray` with these arguments."""
    return [_executable("streaks-ray"), *args]
