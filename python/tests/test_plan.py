"""Tests of the work division (streaks.ray.plan): shards, chunks, the arguments of a task."""

from pathlib import Path

import pytest
from streaks.ray.plan import (
    WHOLE,
    GenerateFlags,
    Shard,
    describe_samples,
    parse_shard,
    plan_chunks,
    sample_folder,
)


def test_parse_shard_reads_k_over_n():
    assert parse_shard("0/1") == WHOLE
    assert parse_shard("3/8") == Shard(3, 8)
    assert parse_shard(" 2 / 5 ") == Shard(2, 5)
    assert str(Shard(3, 8)) == "3/8"


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("3", "not of the form K/N"),
        ("a/b", "whole numbers"),
        ("1/0", "N must be at least 1"),
        ("2/2", "K must be in 0..1"),
        ("-1/4", "K must be in 0..3"),
    ],
)
def test_parse_shard_rejects_bad_shards(text, says):
    with pytest.raises(ValueError, match=says):
        parse_shard(text)


@pytest.mark.parametrize("count", [1, 2, 5, 10, 17, 100])
@pytest.mark.parametrize("shard", [WHOLE, Shard(0, 2), Shard(1, 2), Shard(2, 3), Shard(4, 7)])
@pytest.mark.parametrize("chunk", [1, 2, 3, 8, 1000])
def test_chunks_partition_the_users_shard(count, shard, chunk):
    chunks = plan_chunks(count, shard, chunk)
    wanted = [i for i in range(count) if i % shard.total == shard.index]
    got = sorted(i for c in chunks for i in c.samples)
    assert got == wanted  # every sample of the shard exactly once
    assert [c.number for c in chunks] == list(range(len(chunks)))
    assert all(1 <= len(c.samples) <= chunk for c in chunks)
    # As few tasks as the chunk size allows.
    assert len(chunks) == -(-len(wanted) // chunk)
    for c in chunks:
        # The task's --shard selects exactly its samples.
        assert c.shard.total == shard.total * len(chunks)
        assert c.samples == tuple(i for i in range(count) if i % c.shard.total == c.shard.index)


def test_a_shard_past_the_count_has_no_chunk():
    assert plan_chunks(3, Shard(5, 8), 1) == []


def test_chunk_shards_follow_the_formula():
    # K/M = 1/3, count 20, chunks of 3: samples 1, 4, ..., 19 (7) in 3 tasks.
    chunks = plan_chunks(20, Shard(1, 3), 3)
    assert [str(c.shard) for c in chunks] == ["1/9", "4/9", "7/9"]
    assert [c.samples for c in chunks] == [(1, 10, 19), (4, 13), (7, 16)]


@pytest.mark.parametrize(("count", "chunk"), [(0, 1), (4, 0)])
def test_plan_rejects_zero(count, chunk):
    with pytest.raises(ValueError, match="at least 1"):
        plan_chunks(count, WHOLE, chunk)


def test_arguments_pass_every_flag_through():
    flags = GenerateFlags(
        out=Path("/data/set"),
        count=10,
        seed=7,
        config=Path("/data/street.toml"),
        width=64,
        height=40,
        spp=2,
        max_depth=5,
        noise_target="0.15",
        no_regularize=True,
        denoise="on",
        keep_raw=True,
        outputs="images,gt,kitti",
    )
    assert flags.arguments(Shard(3, 4), 2) == [
        "dataset", "generate", "-o", "/data/set", "--count", "10", "--seed", "7",
        "--config", "/data/street.toml", "--width", "64", "--height", "40", "--spp", "2",
        "--max-depth", "5", "--noise-target", "0.15", "--denoise", "on",
        "--outputs", "images,gt,kitti", "--no-regularize",
        "--keep-raw", "--shard", "3/4", "--threads", "2",
    ]  # fmt: skip


def test_arguments_leave_out_unset_flags():
    flags = GenerateFlags(out=Path("/d"), count=3)
    args = flags.arguments(WHOLE, 1)
    assert args == ["dataset", "generate", "-o", "/d", "--count", "3", "--shard", "0/1"] + [
        "--threads",
        "1",
    ]


def test_descriptions():
    assert describe_samples((5,)) == "sample 5"
    assert describe_samples((1, 5, 9)) == "samples 1, 5, 9"
    assert describe_samples(tuple(range(3, 43, 4))) == "samples 3, 7, ..., 39 (10 samples)"
    assert plan_chunks(8, WHOLE, 2)[3].describe() == "chunk 3 (samples 3, 7)"
    assert sample_folder(42) == "000042"
