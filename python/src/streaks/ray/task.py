"""What one Ray task does: run `streaks dataset generate` for its chunk and report how it went.

This module does not import Ray: the driver wraps `run_renderer` in a Ray task, and the
tests call it directly.
"""

from __future__ import annotations

import signal
import socket
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

STDERR_LINES = 20
"""How many of the renderer's last stderr lines a failure keeps."""


@dataclass(frozen=True)
class RunResult:
    """How one run of the renderer ended."""

    host: str
    """The host name of the node that ran it."""
    seconds: float
    """Wall time of the run."""
    returncode: int | None
    """The renderer's exit status (negative: killed by that signal); None if it did not start."""
    error: str = ""
    """Why the renderer did not start, when it did not."""
    stderr_tail: str = ""
    """The renderer's last stderr lines."""

    @property
    def ok(self) -> bool:
        """True when the renderer ran and exited with status 0."""
        return self.returncode == 0

    def reason(self) -> str:
        """Why the run failed, in a few words (`renderer killed by signal 9 (SIGKILL)`)."""
        if self.returncode is None:
            return self.error
        if self.returncode < 0:
            number = -self.returncode
            try:
                name = f" ({signal.Signals(number).name})"
            except ValueError:
                name = ""
            return f"renderer killed by signal {number}{name} on {self.host}"
        last = self.stderr_tail.strip().splitlines()
        said = f": {last[-1]}" if last else ""
        return f"renderer exited with status {self.returncode} on {self.host}{said}"


def run_renderer(binary: str, args: list[str], out: Path) -> RunResult:
    """Run `binary args...` and wait for it; never raises for a failed or missing renderer.

    `out` is the dataset folder: its parent must exist on this node (on a cluster, a
    filesystem every node shares), else the renderer is not started.
    """
    host = socket.gethostname()
    start = time.monotonic()

    def not_started(error: str) -> RunResult:
        return RunResult(host, time.monotonic() - start, None, error=error)

    if not out.parent.is_dir():
        return not_started(
            f"the output folder's parent {out.parent} does not exist on node {host} "
            "(on a cluster the output folder must be on a filesystem every node shares)"
        )
    try:
        proc = subprocess.run(
            [binary, *args],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            errors="replace",
            check=False,
        )
    except OSError as err:
        return not_started(
            f"cannot run the streaks binary {binary} on node {host}: {err.strerror or err} "
            "(on a cluster it must be at the same path on every node)"
        )
    tail = "\n".join(proc.stderr.splitlines()[-STDERR_LINES:])
    return RunResult(host, time.monotonic() - start, proc.returncode, stderr_tail=tail)
