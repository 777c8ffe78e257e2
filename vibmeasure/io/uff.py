"""Universal File Format dataset 58 (ASCII and binary) through pyuff (the optional extra "uff").

Time responses (function type 1) become a Record; frequency response functions (function type 4)
become an FRF through :func:`read_frf_uff`.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import ParameterError, UnitError
from ..core import units as _units
from ..core.record import Record
from ..core._validate import select_names
from ._common import DEFAULT_MAX_SAMPLES, check_size, make_record, real_samples

_QUANTITY = {8: "displacement", 11: "velocity", 12: "acceleration", 9: "force", 13: "force"}


def _check_complete(path):
    """Every UFF dataset ends with a line "    -1": a file cut inside its last dataset does not."""
    with open(path, "rb") as fh:
        fh.seek(0, 2)
        size = fh.tell()
        fh.seek(max(0, size - 64))
        tail = fh.read()
    if not tail.rstrip().endswith(b"-1"):
        raise ParameterError(f"UFF file {str(path)!r} does not end with the dataset delimiter -1: the file was "
                             "cut inside its last dataset")
    # each dataset opens and closes with a line "    -1": an odd count is a file cut after a dataset's
    # opening line (its tail then ends with -1 too)
    with open(path, "rb") as fh:
        lines = [line.strip() for line in fh]
    n = sum(1 for line in lines if line == b"-1")
    binary = any(line.startswith(b"58b") for line in lines)   # 58b: binary blocks, no line structure to count
    if n % 2 and not binary:
        raise ParameterError(f"UFF file {str(path)!r} has {n} dataset delimiters (-1 lines), an odd number: its "
                             "last dataset was cut after its opening line")


def uff_sets(path):
    """The data sets of a UFF file, read with pyuff after the file is checked complete."""
    _check_complete(path)
    try:
        import pyuff
    except ImportError:
        raise ParameterError("reading .uff needs the optional package pyuff: python -m pip install "
                             "'vibmeasure[uff]'") from None
    try:
        u = pyuff.UFF(str(path))
        types = u.get_set_types()
        idx = [i for i, t in enumerate(types) if int(t) == 58]
        sets = [u.read_sets(i) for i in idx]
    except Exception as exc:  # pyuff raises assorted errors on damaged files
        raise ParameterError(f"UFF file {str(path)!r} is unreadable (truncated or not UFF 58): {exc}") from None
    if not sets:
        raise ParameterError(f"UFF file {str(path)!r} holds no dataset 58 (types found: {sorted(set(types))})")
    return sets


def _unit(label, quantity):
    try:
        u = _units.normalize_unit(str(label).strip())
        if quantity != "unknown" and u and _units.quantity_of(u) != quantity:
            return ""
        return u
    except UnitError:
        return ""


def read_uff(path, *, fs=None, channels=None, quantity=None, unit=None, max_samples=DEFAULT_MAX_SAMPLES) -> Record:
    src = f"UFF file {str(path)!r}"
    sets = uff_sets(path)
    time_sets = [d for d in sets if int(d.get("func_type", 0)) == 1]
    if not time_sets:
        kinds = sorted({int(d.get("func_type", 0)) for d in sets})
        raise ParameterError(f"{src} holds no time response (function types {kinds}); FRFs (type 4) are read "
                             "with vm.read_frf")
    n = {int(d["num_pts"]) for d in time_sets}
    check_size(max(n) * len(time_sets), source=src, max_samples=max_samples)
    for d in time_sets:
        if np.asarray(d["data"]).size != int(d["num_pts"]):
            raise ParameterError(f"{src}: a dataset states {int(d['num_pts'])} points but holds "
                                 f"{np.asarray(d['data']).size} (truncated file?)")
    dx = {float(d["abscissa_inc"]) for d in time_sets}
    if len(n) != 1 or len(dx) != 1:
        raise ParameterError(f"{src}: its time datasets differ in length {sorted(n)} or step {sorted(dx)}")
    file_fs = 1.0 / dx.pop()
    if fs is not None and abs(float(fs) - file_fs) > 1e-6 * file_fs:
        raise ParameterError(f"fs={fs} contradicts {src}, whose abscissa step gives {file_fs:g} Hz")
    names, data, qs, us = [], [], [], []
    for d in time_sets:
        name = str(d.get("rsp_ent_name") or d.get("id1") or f"ch{len(names)}").strip()
        while name in names:
            name += "'"
        names.append(name)
        data.append(real_samples(d["data"], source=f"{src} dataset {name!r}"))
        q = _QUANTITY.get(int(d.get("ordinate_spec_data_type", 0)), "unknown")
        qs.append(q)
        us.append(_unit(d.get("ordinate_axis_units_lab", ""), q))
    pick = select_names(names, channels, source=src)
    return make_record(np.vstack([data[i] for i in pick]), file_fs, [names[i] for i in pick], quantity=quantity,
                       unit=unit, quantities=[qs[i] for i in pick], units=[us[i] for i in pick],
                       t0=float(time_sets[0].get("abscissa_min", 0.0)), meta={"source": str(path)}, source=src)


def read_frf_uff(path):
    """FRFs (function type 4) of a UFF 58 file: one output per dataset, inputs by reference."""
    from ..core.results import FRF
    from ..core.results import form_of
    src = f"UFF file {str(path)!r}"
    sets = [d for d in uff_sets(path) if int(d.get("func_type", 0)) == 4]
    if not sets:
        raise ParameterError(f"{src} holds no FRF dataset (function type 4)")
    freq = np.asarray(sets[0]["x"], float)
    outs = [str(d.get("rsp_ent_name") or d.get("id1")).strip() for d in sets]
    h = np.array([np.asarray(d["data"], complex) for d in sets])
    if h.shape[1] != freq.size:
        raise ParameterError(f"{src}: FRF datasets differ in length")
    q = _QUANTITY.get(int(sets[0].get("ordinate_spec_data_type", 0)), "unknown")
    ref = str(sets[0].get("ref_ent_name") or "force").strip()
    return FRF(freq, h[:, None, :], form_of(q), estimator="file", outputs=tuple(outs), inputs=(ref,),
               params={"source": str(path)})
