"""The ``vibmeasure`` command: parse, call the library, print or write. No analysis here; one module per
command (``register`` its parser, ``run`` it), the exit-code policy written once in main.py."""

from .main import main

__all__ = ["main"]
