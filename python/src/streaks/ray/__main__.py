"""`python -m streaks.ray`: the same as the `streaks-ray` command."""

import sys

from streaks.ray.cli import main

sys.exit(main())
