"""``python -m vibmeasure``: the same command line as ``vibmeasure``."""

import sys

from .cli import main

sys.exit(main())
