"""`python -m beltsim ARGS`: the same as the `beltsim` command."""

import sys

from .cli import main

sys.exit(main())
