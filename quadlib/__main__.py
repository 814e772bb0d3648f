"""``python -m quadlib estimate LOG``: see :mod:`quadlib.cli`."""

import sys

from quadlib.cli import main

sys.exit(main())
