"""pytest: tools/ and tools/blender/ hold plain modules (not packages); put them on the path."""

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
for folder in (HERE, HERE / "blender", HERE / "streak_eval"):
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))
