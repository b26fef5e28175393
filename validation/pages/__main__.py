"""``python -m validation.pages``: see :mod:`validation.pages`."""

import sys

from . import main

sys.exit(main())
