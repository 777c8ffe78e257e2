"""Step: a bearing call must survive its record cut short. A fault's comb is the machine's: it stands
wherever the record happens to end. A call that a cut of 1-2 % of the samples unmakes rests, at least
in part, on how the comb's lines fall between the spectrum's bins. So the family called is tested again
on the record's first CUT_SHARE, shortened to a fast FFT length (1-2 % shorter in all):

- the same family called there: the call stands;
- another family called there: the record reads two faults, and no bearing fault is named (the
  families count against "none" by their p, as an "undetermined" answer's candidates);
- none called, and the family's comb no longer significant there (p above ALPHA): no bearing fault
  is named either;
- none called, yet the comb still significant (its call failed on the views, votes or decoys the
  confidence weighs): the call is named but held under 0.5 (``doubts.unstable_call``).

Every case but the first sets the flag ``bearing_call_unstable``. A ball called from its smeared comb is
tested too: with the other end's bearing declared, CWRU fan-end OR007@12_2 cut by 2 % read ball at 0.95
from humps its shorter record does not show. Measured on the real development records at full length
and cut by 1 and 2 % (benchmarks/diagnosis_cut.py, docs/validation.md)."""

from __future__ import annotations

from dataclasses import replace

from ..bearing import FAMILIES
from ..bearing.rules import ALPHA
from ...core.errors import ParameterError
from ...signal.spectral import fast_len_below
from .bearings import record_evidence
from .lines import TOP_CONFIDENCE
from .speed import Run

CUT_SHARE = 0.99   # the re-test's record: its first 99 %, shortened to a fast FFT length


def survives_a_cut(run: Run, rows: list, ev) -> list:
    """The bearing rows after the call's re-test on the record's first CUT_SHARE (a fast FFT length below
    it): unchanged where it calls the same family; the called family withdrawn (confidence 0,
    ``not_called`` says why) where it calls another or finds no significant comb; else unchanged, the
    re-test kept in ``job.cut_retest`` for the doubt that holds the answer.

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
    short = replace(job, signals={k: v[:n_cut] for k, v in job.signals.items()}, flags=list(job.flags),
                    at_other_speeds=[], cut_retest={})
    try:
        other = record_evidence(short, run, speed_search=None)
    except ParameterError:   # too short to test again: the call stands as the record gives it
        return rows
    fams = other.families
    there = {name: fams[name]["confidence"] for name in FAMILIES if fams[name]["confidence"] >= TOP_CONFIDENCE}
    there_top = max(there, key=there.get) if there else None
    if there_top == here:
        return rows
    p_there = float(fams[here]["p_value"])
    job.flags.append("bearing_call_unstable")
    job.cut_retest.update(family=here, samples=n, cut_to=n_cut, reads=there_top, p_value=p_there)
    if there_top is None and p_there <= ALPHA:
        return rows   # held by ``doubts.unstable_call``
    read = (f"calls {there_top} at {there[there_top]:.2f}" if there_top else
            f"calls no family (its comb p = {p_there:.2g})")
    for r in rows:
        if r["fault"] in called:
            r["not_called"] = "; ".join(filter(None, [
                f"called on the {n} samples but the test on the first {n_cut} ({100 * n_cut / n:.1f} %) {read}: "
                "the comb rests on where the record ends, not on the bearing (a longer record, or another, "
                "should settle it)", r.get("not_called")]))
            r["confidence"] = 0.0
    return rows
