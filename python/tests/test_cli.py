"""The command's errors: bad flags, a missing or wrong binary, no cluster. No Ray cluster is
started here, and nothing is written."""

import subprocess
import time

import pytest
from conftest import TINY, free_port, ray_env, streaks_ray
from streaks.ray.cli import main


def _generate(*args):
    return main(["generate", "--address", "127.0.0.1:1", *args])


@pytest.mark.parametrize(
    ("shard", "says"),
    [
        ("3/2", "K must be in 0..1"),
        ("a/b", "whole numbers"),
        ("1/0", "N must be at least 1"),
        ("2", "not of the form K/N"),
    ],
)
def test_a_bad_shard_is_a_usage_error(tmp_path, capsys, shard, says):
    with pytest.raises(SystemExit) as stop:
        _generate("-o", str(tmp_path / "d"), "--count", "4", "--shard", shard)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "argument --shard" in err and says in err
    assert not (tmp_path / "d").exists()


@pytest.mark.parametrize(
    ("flags", "says"),
    [
        (["--count", "0"], "argument --count: 0 is less than 1"),
        (["--count", "4", "--num-cpus", "0"], "argument --num-cpus: 0 is less than 1"),
        (["--count", "4", "--chunk", "x"], "argument --chunk: 'x' is not a whole number"),
        (["--count", "4", "--max-retries", "-1"], "argument --max-retries: -1 is less than 0"),
        (["--count", "4", "--threads", "2"], "unrecognized arguments: --threads 2"),
        (["--count", "4", "--noise-target", "low"], "'low' is neither a number nor off"),
        (["--count", "4", "--noise-target", "0"], "0 is not a positive, finite number"),
        ([], "the following arguments are required: --count"),
    ],
)
def test_bad_flags_are_usage_errors(tmp_path, capsys, flags, says):
    with pytest.raises(SystemExit) as stop:
        _generate("-o", str(tmp_path / "d"), *flags)
    assert stop.value.code == 2
    assert says in capsys.readouterr().err


def test_a_missing_binary_is_reported(tmp_path, capsys):
    missing = tmp_path / "bin" / "streaks"
    assert _generate("--streaks-bin", str(missing), "-o", str(tmp_path / "d"), *TINY) == 1
    err = capsys.readouterr().err
    assert f"streaks-ray: error: streaks binary '{missing}' not found at that path" in err
    assert not (tmp_path / "d").exists()


def test_a_binary_not_on_path_is_reported(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))
    assert _generate("-o", str(tmp_path / "d"), *TINY) == 1
    assert "streaks binary 'streaks' not found on PATH (give --streaks-bin" in (
        capsys.readouterr().err
    )


def test_a_binary_that_is_not_streaks_is_reported(tmp_path, capsys):
    assert _generate("--streaks-bin", "/bin/false", "-o", str(tmp_path / "d"), *TINY) == 1
    assert "/bin/false --version exited with status 1" in capsys.readouterr().err


def test_an_output_folder_without_parent_is_reported(tmp_path, capsys, streaks_bin):
    out = tmp_path / "no" / "d"
    assert _generate("--streaks-bin", streaks_bin, "-o", str(out), *TINY) == 1
    assert f"its parent folder {out.parent} does not exist" in capsys.readouterr().err


def test_a_missing_config_is_reported(tmp_path, capsys, streaks_bin):
    config = tmp_path / "street.toml"
    args = ["--streaks-bin", streaks_bin, "-o", str(tmp_path / "d"), "--config", str(config)]
    assert _generate(*args, *TINY) == 1
    assert f"config {config} is not a file" in capsys.readouterr().err


def test_a_shard_without_samples_is_reported(tmp_path, capsys, streaks_bin):
    args = ["--streaks-bin", streaks_bin, "-o", str(tmp_path / "d"), "--count", "2"]
    assert _generate(*args, "--shard", "3/4") == 1
    assert "--shard 3/4 selects no sample of --count 2" in capsys.readouterr().err


def test_no_cluster_at_the_address_is_reported_quickly(tmp_path, streaks_bin):
    address = f"127.0.0.1:{free_port()}"
    start = time.monotonic()
    run = subprocess.run(
        streaks_ray("generate", "--address", address, "--streaks-bin", streaks_bin)
        + ["-o", str(tmp_path / "d"), *TINY],
        env=ray_env(),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 1
    assert f"streaks-ray: error: no Ray cluster at {address}: cannot connect" in run.stderr
    assert time.monotonic() - start < 30
    assert not (tmp_path / "d").exists()
