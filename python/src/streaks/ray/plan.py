"""Work division: the user's `--shard K/M` split into one `--shard` per Ray task.

`streaks dataset generate --shard K/N` renders the samples whose index i satisfies
i = K (mod N). With T tasks, task t runs `--shard (K + t*M)/(M*T)`: the residues K + t*M
modulo M*T for t = 0 .. T-1 are exactly the residues modulo M*T that are K modulo M, so the
tasks partition the user's shard, each sample in exactly one task. T is chosen so that each
task has at most `--chunk` samples and none has zero.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Shard:
    """A shard `index/total` of `streaks dataset generate`: the samples i = index (mod total)."""

    index: int
    total: int

    def __post_init__(self) -> None:
        if self.total < 1:
            raise ValueError(f"a shard's total must be at least 1, not {self.total}")
        if not 0 <= self.index < self.total:
            raise ValueError(f"a shard's index must be in 0..{self.total - 1}, not {self.index}")

    def __str__(self) -> str:
        return f"{self.index}/{self.total}"

    def samples(self, count: int) -> range:
        """The sample indices of this shard in a dataset of `count` samples."""
        return range(self.index, count, self.total)


WHOLE = Shard(0, 1)
"""The shard of every sample (what `streaks dataset generate` renders without `--shard`)."""


def parse_shard(text: str) -> Shard:
    """Parse `K/N` (0 <= K < N) as `streaks dataset generate --shard` takes it.

    Raises ValueError with a message that says what is wrong.
    """
    index, slash, total = text.partition("/")
    if not slash:
        raise ValueError(f"'{text}' is not of the form K/N (for example 0/4)")
    try:
        k, n = int(index.strip()), int(total.strip())
    except ValueError:
        raise ValueError(f"'{text}' is not of the form K/N with whole numbers K and N") from None
    if n < 1:
        raise ValueError(f"'{text}': N must be at least 1")
    if not 0 <= k < n:
        raise ValueError(f"'{text}': K must be in 0..{n - 1}")
    return Shard(k, n)


@dataclass(frozen=True)
class Chunk:
    """One Ray task's work: a sub-shard of the user's shard."""

    number: int
    """The task's number t, 0 .. tasks-1."""
    shard: Shard
    """The `--shard` the task passes to `streaks dataset generate`."""
    samples: tuple[int, ...]
    """The sample indices the task renders."""

    def describe(self) -> str:
        """`chunk 3 (samples 3, 7)`, with long sample lists shortened."""
        return f"chunk {self.number} ({describe_samples(self.samples)})"


def describe_samples(samples: tuple[int, ...]) -> str:
    """`samples 3, 7, 11` or, for more than four, `samples 3, 7, ..., 39 (10 samples)`."""
    if len(samples) == 1:
        return f"sample {samples[0]}"
    if len(samples) <= 4:
        return "samples " + ", ".join(str(i) for i in samples)
    return f"samples {samples[0]}, {samples[1]}, ..., {samples[-1]} ({len(samples)} samples)"


def plan_chunks(count: int, shard: Shard, chunk_size: int) -> list[Chunk]:
    """Split the samples of `shard` in a dataset of `count` into tasks of at most `chunk_size`.

    Returns no chunk when the shard has no sample (its index is `count` or more).
    """
    if count < 1:
        raise ValueError(f"the sample count must be at least 1, not {count}")
    if chunk_size < 1:
        raise ValueError(f"the chunk size must be at least 1, not {chunk_size}")
    wanted = len(shard.samples(count))
    tasks = -(-wanted // chunk_size)
    chunks = []
    for t in range(tasks):
        sub = Shard(shard.index + t * shard.total, shard.total * tasks)
        chunks.append(Chunk(t, sub, tuple(sub.samples(count))))
    return chunks


@dataclass(frozen=True)
class GenerateFlags:
    """The flags of `streaks dataset generate` that the driver passes to every task unchanged."""

    out: Path
    """The dataset folder, absolute (every node must see it at this path)."""
    count: int
    seed: int | None = None
    config: Path | None = None
    """The generator config, absolute (every node must see it at this path)."""
    width: int | None = None
    height: int | None = None
    spp: int | None = None
    max_depth: int | None = None
    noise_target: str | None = None
    """Adaptive sampling's target: a positive number as text, or `off`."""
    no_regularize: bool = False
    denoise: str | None = None
    """`auto`, `on` or `off` (`streaks dataset generate --denoise`); on a cluster give `on` or
    `off`, so that every node denoises alike."""
    keep_raw: bool = False
    outputs: str | None = None
    """The groups of files each sample keeps (`streaks dataset generate --outputs`), as the
    comma-separated list the command takes; the command checks the names."""

    def arguments(self, shard: Shard, threads: int) -> list[str]:
        """The arguments after the binary: `dataset generate -o DIR --count N ... --shard K/N`."""
        args = ["dataset", "generate", "-o", str(self.out), "--count", str(self.count)]
        optional: list[tuple[str, object]] = [
            ("--seed", self.seed),
            ("--config", self.config),
            ("--width", self.width),
            ("--height", self.height),
            ("--spp", self.spp),
            ("--max-depth", self.max_depth),
            ("--noise-target", self.noise_target),
            ("--denoise", self.denoise),
            ("--outputs", self.outputs),
        ]
        for flag, value in optional:
            if value is not None:
                args += [flag, str(value)]
        if self.no_regularize:
            args.append("--no-regularize")
        if self.keep_raw:
            args.append("--keep-raw")
        return args + ["--shard", str(shard), "--threads", str(threads)]


def sample_folder(index: int) -> str:
    """The name of sample `index`'s folder under DIR/samples/ (`000042`)."""
    return f"{index:06d}"
