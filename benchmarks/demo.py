"""The demo's run time and report size (issue 14: under 60 s on a 2-core machine).

    python benchmarks/demo.py
"""

import tempfile
import time
from pathlib import Path

from vibmeasure.reporting import demo

if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = demo(Path(tmp) / "demo")
        first = time.perf_counter() - t0
        t0 = time.perf_counter()
        demo(Path(tmp) / "demo")  # inputs reused, stored measurements skipped
        again = time.perf_counter() - t0
        print(f"vibmeasure demo: {first:.1f} s from nothing (target 60 s), {again:.1f} s again; "
              f"report {res['size_bytes'] / 1e6:.2f} MB, one self-contained HTML file")
