"""``python -m vibmeasure.cli``: the command line."""

from .main import main

raise SystemExit(main())
