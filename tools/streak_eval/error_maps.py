"""Copies the left thumbnails and the error maps of chosen samples out of `streaks benchmark`
pages (index.html holds them as PNG data URIs, named by their alt text) into PNG files, for
the docs' before-and-after figures.

    python3 tools/streak_eval/error_maps.py OUTDIR PAGE SAMPLE [PAGE SAMPLE ...]

writes OUTDIR/SAMPLE_left.png and OUTDIR/SAMPLE_METHOD.png for every method on the page (the
colours are the benchmark's: docs/stereo-benchmark.md).
"""

from __future__ import annotations

import base64
import re
import sys
from pathlib import Path

IMG = re.compile(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)"[^>]*?alt="([^"]*)"')


def images(page: Path) -> dict[str, bytes]:
    """The page's images by alt text."""
    text = page.read_text(encoding="utf-8")
    return {alt: base64.b64decode(data) for data, alt in IMG.findall(text)}


def extract(out: Path, page: Path, sample: str) -> list[Path]:
    """Writes the sample's left image and error maps; returns the files."""
    found = images(page)
    written = []
    for alt, png in found.items():
        name = None
        if alt == f"left image of {sample}":
            name = f"{sample}_left.png"
        elif alt.endswith(f" error map of {sample}"):
            name = f"{sample}_{alt.removesuffix(f' error map of {sample}')}.png"
        if name is not None:
            (out / name).write_bytes(png)
            written.append(out / name)
    if not any(p.name.startswith(f"{sample}_") for p in written):
        sys.exit(f"{page}: no images of sample {sample!r}")
    return written


def main() -> None:
    """Extracts the images named on the command line."""
    args = sys.argv[1:]
    if len(args) < 3 or len(args) % 2 == 0:
        sys.exit("usage: error_maps.py OUTDIR PAGE SAMPLE [PAGE SAMPLE ...]")
    out = Path(args[0])
    out.mkdir(parents=True, exist_ok=True)
    for page, sample in zip(args[1::2], args[2::2], strict=False):
        for p in extract(out, Path(page), sample):
            print(p)


if __name__ == "__main__":
    main()
