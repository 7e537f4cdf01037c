"""Tests of one task's run (streaks.ray.task.run_renderer) with small shell scripts as renderer."""

import stat
from pathlib import Path

from streaks.ray.task import STDERR_LINES, run_renderer


def _script(folder: Path, body: str) -> str:
    path = folder / "renderer.sh"
    path.write_text("#!/bin/sh\n" + body)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return str(path)


def test_a_renderer_that_succeeds(tmp_path):
    script = _script(tmp_path, 'echo "$@" > "$(dirname "$0")/args"\n')
    result = run_renderer(script, ["dataset", "generate", "--shard", "1/2"], tmp_path / "out")
    assert result.ok and result.returncode == 0
    assert (tmp_path / "args").read_text() == "dataset generate --shard 1/2\n"


def test_a_renderer_that_fails_keeps_its_last_stderr_lines(tmp_path):
    script = _script(
        tmp_path, 'i=0; while [ $i -lt 30 ]; do echo "line $i" >&2; i=$((i+1)); done\nexit 3\n'
    )
    result = run_renderer(script, [], tmp_path / "out")
    assert not result.ok and result.returncode == 3
    assert result.stderr_tail.splitlines() == [f"line {i}" for i in range(30 - STDERR_LINES, 30)]
    assert result.reason() == f"renderer exited with status 3 on {result.host}: line 29"


def test_a_killed_renderer_names_the_signal(tmp_path):
    result = run_renderer(_script(tmp_path, "kill -9 $$\n"), [], tmp_path / "out")
    assert result.returncode == -9
    assert result.reason() == f"renderer killed by signal 9 (SIGKILL) on {result.host}"


def test_a_missing_renderer_is_reported(tmp_path):
    result = run_renderer(str(tmp_path / "no-streaks"), [], tmp_path / "out")
    assert result.returncode is None and not result.ok
    assert "cannot run the streaks binary" in result.reason()
    assert "same path on every node" in result.reason()


def test_an_output_folder_the_node_cannot_see_is_reported(tmp_path):
    script = _script(tmp_path, 'touch "$(dirname "$0")/ran"\n')
    result = run_renderer(script, [], tmp_path / "missing" / "out")
    assert result.returncode is None
    assert "does not exist on node" in result.reason()
    assert not (tmp_path / "ran").exists()  # the renderer was not started
