"""`python -m streaks_ray`: the same as the `streaks-ray` command."""

import sys

from streaks_ray.cli import main

sys.exit(main())
