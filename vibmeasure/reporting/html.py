"""Which analysis each input gets (``analyse_input``), and the self-contained page (``report``)."""

from __future__ import annotations

import datetime as _dt
import platform
from pathlib import Path

import numpy as np

from ..core.dispatch import analysis_for
from ..core.errors import ParameterError, VibMeasureError
from ..io._common import file_sha256
from .given import is_result, result_sections
from .sections import (comparison_section, diagnosis_section, error_section, fleet_section, modes_section,
                       ringdown_section)


# --- analysing an input by what it holds ----------------------------------------------------------
def analyse_input(item, *, rpm=None, bearing=None, band=None, model=None, fs=None, unit=None, channels=None,
                  input=None):
    """Sections for one file or record, by what it holds (``core.dispatch.analysis_for``, after
    ``core.dispatch.load_input`` applied ``fs``, ``unit``, ``channels`` and the force channel
    ``input``): an FRF/modes section when it has a force channel, a diagnosis when a shaft speed is
    known (``rpm`` or the file's rpm), else a ring-down; plus a comparison when a model (TOML) is
    given. Returns (sections, provenance row)."""
    import warnings

    from ..core.dispatch import load_input
    from ..identify.frf import estimate_frf, impact_frf
    from ..identify.modal import fit_modes
    from ..identify.ringdown import ringdown
    from ..monitor.compare import compare
    from ..monitor.diagnosis import diagnose
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec, name = load_input(item, fs=fs, unit=unit, channels=channels, input=input)
        forces = [c.name for c in rec.channels if c.quantity == "force"]
        if input is not None:   # the named input first: a record may hold other force channels
            forces.insert(0, rec.channels[rec.index(input)].name)
        speed = rpm if rpm is not None else rec.meta.get("rpm")
        secs, method = [], ""
        kind = analysis_for(rec, rpm=rpm)
        if kind == "modes":
            try:
                frf = impact_frf(rec, input=forces[0])
                how = "impact_frf"
            except VibMeasureError:
                frf, how = estimate_frf(rec, input=forces[0]), "estimate_frf"
            b = band or (max(1.0, 4 * float(frf.freq[1])), 0.4 * rec.fs)
            est = fit_modes(frf, band=tuple(b))
            secs.append(modes_section(frf, est, name))
            method = f"{how} (input {forces[0]}) + fit_modes band {b[0]:.4g}-{b[1]:.4g} Hz"
        elif kind == "diagnose":
            diag = diagnose(rec, rpm=float(speed), bearing=bearing)
            secs.append(diagnosis_section(rec, diag, name))
            method = f"diagnose rpm {float(speed):.6g}, bearing {bearing or 'not given'}"
            est = None
        else:
            est = ringdown(rec, band=band)
            secs.append(ringdown_section(rec, est, name))
            method = "ringdown (maximum likelihood)" + (f", band {band}" if band else "")
        if model is not None and est is not None:
            from ..models.loader import load
            what = f"{name} vs {Path(model).name}"
            try:  # a bad model is listed; the analysis of the record still stands
                secs.append(comparison_section(compare(est, load(model)), what))
                method += f"; compare with {Path(model).name}"
            except (VibMeasureError, OSError, ValueError) as exc:
                secs.append(error_section(f"comparison {what}", exc))
    return secs, {"input": name, "sha256": _sha(item), "method": method}


def _sha(item) -> str:
    """The provenance hash: a file's SHA-256, or a record's samples' (a record has no file)."""
    from ..core.record import Record
    if isinstance(item, Record):
        import hashlib
        return hashlib.sha256(np.ascontiguousarray(item.data).tobytes()).hexdigest()
    return file_sha256(item) if Path(str(item)).is_file() else "(missing)"


def report(inputs=(), out="report.html", *, store=None, title: str = "Vibration measurement report", rpm=None,
           bearing=None, band=None, model=None, summary=None, failures: list | None = None, fs=None, unit=None,
           channels=None, input=None) -> Path:
    """Write a self-contained HTML report of records and, with ``store``, the fleet trends.

    Each input gets the section its content calls for (``core.dispatch.analysis_for``); an input that
    cannot be analysed is listed with its error and the others are still reported. Written atomically.

    Parameters
    ----------
    inputs : sequence of str, os.PathLike, Record or result
        Record files and/or records, each analysed by what it holds; and/or results computed already
        (a ModalEstimate, Diagnosis or Comparison), reported as they are, alone or paired with their
        source for the figures: ``(record, estimate)``, ``(record, diagnosis)``, ``(frf, estimate)``.
        A single one is taken as a list of one.
    out : str or os.PathLike
        The HTML file.
    store : str, os.PathLike or Store, optional
        A store whose fleet trends are reported too.
    title : str
        The report's title.
    rpm : float, optional
        Shaft speed: records are diagnosed as machines.
    bearing : str or Bearing, optional
        The bearing for the diagnosis.
    band : tuple of float, optional
        (lo, hi) Hz for ringdown and fit_modes.
    model : str or os.PathLike, optional
        A TOML model each estimate is compared with.
    summary : list of str, optional
        Lines for the report's summary.
    failures : list, optional
        When given, the name and error of each input (or the store) that could not be analysed is
        appended to it as ``(name, message)``: the report is written all the same.
    fs : float, optional
        Sampling rate of files that carry no timing (a CSV without a time column, a WAV-less array).
    unit : str, optional
        Unit of the data of files that do not say (e.g. "g").
    channels : str or sequence of str, optional
        The channels analysed (default every channel).
    input : str, optional
        The force channel of a hammer or shaker test: the record is reported as FRFs and modes.

    Returns
    -------
    pathlib.Path
        The report written.

    Raises
    ------
    ParameterError
        For nothing to report, or an output folder that does not exist.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import vibmeasure as vm
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = vm.write(folder / "decay.h5", vm.synth.free_decay(fn=12.0, zeta=0.02, fs=500.0, duration=6.0, seed=1))
    >>> vm.report([folder / "decay.h5"], folder / "r.html").suffix
    '.html'
    >>> rec = vm.synth.free_decay(fn=20.0, zeta=0.01, fs=1000.0, duration=4.0, seed=2)
    >>> vm.report([(rec, vm.ringdown(rec))], folder / "given.html").name   # a result computed already
    'given.html'
    """
    import jinja2
    import scipy

    from .. import __version__
    from ..io._common import atomic_path
    from ..plot import file_backend
    out = Path(out)
    if not out.parent.exists():
        raise ParameterError(f"out={str(out)!r}: folder {str(out.parent)!r} does not exist")
    from ..core.record import Record
    if isinstance(inputs, (str, Path, Record)) or is_result(inputs):
        inputs = [inputs]
    file_backend()
    sections, prov = [], []
    for i, p in enumerate(inputs):
        label = _label(p, i)
        try:
            if is_result(p):   # computed already: reported as it is, never analysed again
                secs, row = result_sections(p, i)
            else:
                secs, row = analyse_input(p, rpm=rpm, bearing=bearing, band=band, model=model, fs=fs, unit=unit,
                                          channels=channels, input=input)
            sections += secs
            prov.append(row)
        except Exception as exc:   # noqa: BLE001 - one input's failure is its section, never the report's
            sections.append(error_section(label, exc))
            if failures is not None:
                failures.append((str(p) if isinstance(p, (str, Path)) else label, f"{type(exc).__name__}: {str(exc)[:300]}"))
            prov.append({"input": label, "sha256": "(result)" if is_result(p) else _sha(p), "method": "not analysed"})
    if store is not None:
        try:
            name, digest = _store_provenance(store)
            sections.append(fleet_section(store, name))
            prov.append({"input": name, "sha256": digest, "method": "trend"})
        except Exception as exc:   # noqa: BLE001 - the fleet's failure is its section, never the report's
            sections.append(error_section(str(store), exc))
            if failures is not None:
                failures.append((str(store), f"{type(exc).__name__}: {str(exc)[:300]}"))
    if not sections:
        raise ParameterError("nothing to report: give input files and/or a store")
    env = jinja2.Environment(loader=jinja2.PackageLoader("vibmeasure.reporting", "templates"),
                             autoescape=jinja2.select_autoescape(["html", "j2"]))
    html = env.get_template("report.html.j2").render(
        title=title, version=__version__, created=_dt.datetime.now().strftime("%Y-%m-%d %H:%M"),
        sections=sections, provenance=prov, summary=summary or [], python=platform.python_version(),
        numpy=np.__version__, scipy=scipy.__version__)
    with atomic_path(out) as tmp:
        tmp.write_text(html, encoding="utf-8")
    return out


def _label(item, i: int) -> str:
    """How an input is named on the page: a record's source, a result's kind, a file's name."""
    from ..core.record import Record
    if isinstance(item, Record):
        return str(item.meta.get("source") or "record")
    if is_result(item) or not isinstance(item, (str, Path)):
        return f"{type(item).__name__} (input {i + 1})"
    return Path(str(item)).name


def _store_provenance(store) -> tuple[str, str]:
    """(name, SHA-256) of a store for the report's provenance: a file's own hash; a database server's
    store is named by its host and database (never its credentials) and has no file to hash."""
    from ..io.sql import is_sql_target
    target = getattr(store, "target", None) or getattr(store, "path", None) or store
    if is_sql_target(target) and "://" in str(target) and not str(target).startswith("sqlite"):
        return str(target).split("@")[-1].split("://")[-1], "(database server)"
    path = Path(getattr(store, "path", target))
    return path.name, file_sha256(path)

