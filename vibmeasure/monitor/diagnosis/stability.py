"""Step: a bearing call must survive its record cut short. A fault's comb is the machine's: it stands
wherever the record happens to end. A comb that a cut of 1-2 % of the samples makes or unmakes rests on
how its lines fall between the spectrum's bins, not on the bearing. So the family called is tested
again on the record's first CUT_SHARE (to a fast FFT length, 1-2 % shorter); where that test calls
another family or none, no bearing fault is named (``bearing_call_unstable``) and the family counts
against "none" by its p, as an "undetermined" answer's candidate.

Measured on the real development records (benchmarks/diagnosis_real.py; docs/validation.md): no right
call lost; with the other end's bearing declared, two of four false calls withdrawn (CWRU fan-end
OR007@12_0 outer race at 1.00, OR021@6_0 ball at 0.69); fan-end B021_3 (ball) cut by 1 % read outer
race at 1.00 and is now withdrawn."""

from __future__ import annotations

from dataclasses import replace

from ..bearing import FAMILIES
from ...core.errors import ParameterError
from ...signal.spectral import fast_len_below
from .bearings import record_evidence
from .lines import TOP_CONFIDENCE
from .speed import Run

CUT_SHARE = 0.99   # the re-test's record: its first 99 %, shortened to a fast FFT length


def survives_a_cut(run: Run, rows: list, ev) -> list:
    """The bearing rows, with the family called withdrawn (confidence 0, ``not_called`` says why) where
    the test on the record's first CUT_SHARE (a fast FFT length below it) does not call it too.

    Examples
    --------
    >>> import vibmeasure as vm
    >>> rec = vm.synth.machine(fault="bearing_inner_race", rpm=1797, duration=4.0, seed=1)
    >>> d = vm.diagnose(rec, rpm=1797, bearing="6205-2RS")
    >>> d.top, "bearing_call_unstable" in d.flags
    ('bearing_inner_race', False)
    """
    called = {r["fault"]: r["confidence"] for r in rows if r["fault"] in FAMILIES and r["confidence"] >= TOP_CONFIDENCE}
    if ev is None or not called:
        return rows
    here = max(called, key=called.get)
    job = run.job
    n = len(next(iter(job.signals.values())))
    n_cut = fast_len_below(int(CUT_SHARE * n), real=False)
    short = replace(job, signals={k: v[:n_cut] for k, v in job.signals.items()}, flags=list(job.flags))
    try:
        other = record_evidence(short, run, speed_search=None)
    except ParameterError:   # too short to test again: the call stands as the record gives it
        return rows
    there = {name: s["confidence"] for name, s in other.families.items()
             if name in FAMILIES and s["confidence"] >= TOP_CONFIDENCE}
    there_top = max(there, key=there.get) if there else None
    if there_top == here:
        return rows
    read = f"calls {there_top} at {there[there_top]:.2f}" if there_top else "calls no family"
    run.job.flags.append("bearing_call_unstable")
    for r in rows:
        if r["fault"] in called:
            r["not_called"] = "; ".join(filter(None, [
                f"called on the {n} samples but the test on the first {n_cut} ({100 * n_cut / n:.1f} %) {read}: "
                "the comb rests on where the record ends, not on the bearing (a longer record, or another, "
                "should settle it)", r.get("not_called")]))
            r["confidence"] = 0.0
    return rows
