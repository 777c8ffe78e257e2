"""Self-contained HTML reports (vm.report; the package is reporting/, not report/,
so that importing it never hides the function vm.report): what an engineer hands to colleagues.

One file, no network assets: CSS inline, every figure an inline SVG drawn by vibmeasure.plot (the same
picture a user makes in Python), readable on a phone and printable. Sections follow what the inputs
hold: a ring-down, an FRF with its modes, a machine diagnosis, a comparison with a model or a
baseline, and fleet trends from a :class:`vibmeasure.Store`. Every quality flag is explained in
plain words with what to do about it. Provenance (software version, method and parameters, input
file hashes) closes the report. The HTML comes from a Jinja2 template (templates/report.html.j2). Modules: sections.py (one section per kind of result),
html.py (which analysis each input gets, and the page), demo.py (the main job on synthesised inputs).
"""

from .demo import demo
from .html import analyse_input, report
from .sections import FLAG_ADVICE

__all__ = ["report", "demo", "analyse_input", "FLAG_ADVICE"]
