"""streaks-ray: run `streaks dataset generate` on a Ray cluster.

The driver splits the samples of one `streaks dataset generate` call into Ray tasks by shards,
runs the `streaks` binary in each task, retries the tasks that fail, shows the progress over
samples and runs `streaks dataset index --rebuild` at the end (see python/README.md).
"""

__version__ = "0.1.0"
