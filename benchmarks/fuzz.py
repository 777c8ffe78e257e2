"""Damaged and hostile files through vm.read: per format, the count of cases and their outcomes.

Each base file is written by vibmeasure (CSV, HDF5, WAV) or built like a third-party file (MATLAB v5
and v7.3, LabVIEW .lvm, UFF 58), then mutated: cut at every line end and inside the last field, cut at
random bytes, single flipped bytes, inserted and deleted bytes, and crafted headers (huge declared
sizes, contradicting rates). Every case runs in a worker process with a time limit, so a crash or a
hang inside a parser is counted, not suffered.

Outcomes: named (ParameterError), exact (the original data, e.g. a flip in padding), flagged (read
with a QualityWarning), raw (any other exception: a defect), silent (read, different data, no
warning: a defect), crash (the worker died), hang (over the time limit).

    python benchmarks/fuzz.py [--flips N] [--seed S] [--timeout SECONDS]
"""

import argparse
import multiprocessing as mp
import random
import struct
import tempfile
import time
import warnings
from collections import Counter
from pathlib import Path

import numpy as np

OUTCOMES = ("named", "exact", "flagged", "raw", "silent", "crash", "hang")


def base_files(folder: Path) -> dict:
    """format -> (path of an intact file, the data it must read as)."""
    import h5py
    import scipy.io as sio
    import vibmeasure as vm
    rng = np.random.default_rng(1)
    data = np.round(rng.normal(size=(2, 400)), 6)
    rec = vm.Record(data, 1000.0, [vm.Channel("a", "acceleration", "g"), vm.Channel("b", "velocity", "m/s")])
    out = {}
    out["csv"] = (vm.write(folder / "base.csv", rec), data)
    out["h5"] = (vm.write(folder / "base.h5", rec), data)
    out["wav"] = (vm.write(folder / "base.wav", rec), data)
    sio.savemat(folder / "base.mat", {"acc": data, "fs": 1000.0})
    out["mat"] = (folder / "base.mat", data)
    with h5py.File(folder / "base73.mat", "w", userblock_size=512) as f:   # the v7.3 layout
        f["acc"] = data.T
        f["fs"] = np.array([[1000.0]])
    with open(folder / "base73.mat", "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, written by fuzz".ljust(116) + b"\0" * 8 + b"\x00\x02IM")
    out["mat73"] = (folder / "base73.mat", data)
    lines = ["LabVIEW Measurement\t", "Writer_Version\t2", "Separator\tTab", "Decimal_Separator\t.",
             "***End_of_Header***\t", "", "Channels\t2\t", "Samples\t400\t400\t", "Delta_X\t0.001\t0.001\t",
             "X0\t0\t0\t", "***End_of_Header***\t", "X_Value\ta\tb\tComment"]
    lines += [f"{i / 1000:.3f}\t{float(data[0, i])!r}\t{float(data[1, i])!r}" for i in range(data.shape[1])]
    (folder / "base.lvm").write_text("\n".join(lines) + "\n")
    out["lvm"] = (folder / "base.lvm", data)
    try:
        import pyuff
        u = pyuff.UFF(str(folder / "base.uff"))
        for i in range(2):
            u.write_sets(pyuff.prepare_58(func_type=1, rsp_node=i + 1, rsp_dir=1, ref_node=0, ref_dir=0,
                                          abscissa_spacing=1, data=data[i], x=np.arange(400) / 1000.0,
                                          id1=f"ch{i}", rsp_ent_name=f"ch{i}", ordinate_spec_data_type=12,
                                          orddenom_spec_data_type=0, abscissa_spec_data_type=17,
                                          binary=0, num_pts=400, abscissa_inc=0.001, abscissa_min=0.0),
                         mode="add")
        out["uff"] = (folder / "base.uff", data)
    except Exception:  # pyuff is an optional extra
        pass
    return out


def mutations(raw: bytes, fmt: str, n_flips: int, rng: random.Random):
    """(label, bytes) of every mutated file for one base file."""
    ends = [i + 1 for i, b in enumerate(raw) if b == 0x0A]
    text_like = fmt in ("csv", "lvm", "uff")
    if text_like:
        for e in ends[:-1]:
            yield "cut at line end", raw[:e]
        last = ends[-2] if len(ends) > 1 else 0
        for k in range(last + 1, len(raw) - 1):
            yield "cut inside last line", raw[:k]
    for _ in range(n_flips // 4):
        yield "cut at random byte", raw[:rng.randrange(1, len(raw))]
    for _ in range(n_flips):
        b = bytearray(raw)
        pos = rng.randrange(len(raw))
        b[pos] ^= 1 << rng.randrange(8)
        yield "flipped byte", bytes(b)
    for _ in range(n_flips // 4):
        pos = rng.randrange(len(raw))
        yield "inserted byte", raw[:pos] + bytes([rng.randrange(256)]) + raw[pos:]
        yield "deleted byte", raw[:pos] + raw[pos + 1:]
    yield from crafted(raw, fmt)


def _crafted_h5(**kw) -> bytes:
    """A record file in vibmeasure's schema, unsealed, with one part wrong (the lazy path's cases)."""
    import h5py
    data = kw.pop("data", np.zeros((2, 100)))
    names = kw.pop("names", ("a", "b"))
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "c.h5"
        with h5py.File(p, "w") as f:
            f.attrs["vibmeasure_schema"] = "vibmeasure.record"
            f.attrs["schema_version"] = 1
            f.attrs["meta"] = kw.pop("meta", "{}")
            if not kw.pop("no_data", False):
                d = f.create_dataset("data", data=data)
                attrs = {"fs": kw.pop("fs", 100.0), "t0": 0.0, "channel_names": list(names),
                         "channel_quantities": ["unknown"] * len(names), "channel_units": [""] * len(names),
                         "channel_locations": [""] * len(names)}
                for k, v in attrs.items():
                    if k not in kw.get("drop", ()):
                        d.attrs[k] = v
        return p.read_bytes()


def crafted(raw: bytes, fmt: str):
    if fmt == "h5":
        yield "no names", _crafted_h5(drop=("channel_names",))
        yield "fs as text", _crafted_h5(fs="abc")
        yield "fs negative", _crafted_h5(fs=-5.0)
        yield "bad JSON meta", _crafted_h5(meta="{not json")
        yield "complex data", _crafted_h5(data=np.zeros((2, 100)) + 1j)
        yield "empty data", _crafted_h5(data=np.zeros((2, 0)))
        yield "3 names for 2 rows", _crafted_h5(names=("a", "b", "c"))
        yield "no data", _crafted_h5(no_data=True)
    if fmt == "wav":
        b = bytearray(raw)
        i = raw.find(b"data")
        if i > 0:
            b[i + 4: i + 8] = struct.pack("<I", 0xFFFFFFF0)   # a data chunk declaring 4 GiB
            yield "declares 4 GiB", bytes(b)
        j = raw.find(b"fmt ")
        if j > 0:
            for bits in (0, 12):
                b = bytearray(raw)
                b[j + 8 + 14: j + 8 + 16] = struct.pack("<H", bits)
                yield f"{bits} bits per sample", bytes(b)
            if i > 0:
                b = bytearray(raw[:i + 8])
                b[i + 4: i + 8] = struct.pack("<I", 0)
                yield "empty data chunk", bytes(b)
    if fmt == "csv":
        txt = raw.decode()
        yield "fs with thousands separator", txt.replace("# fs_hz = 1000.0", "# fs_hz = 1,000").encode()
        yield "two fs values", txt.replace("# fs_hz = 1000.0", "# fs_hz = 1000.0\n# sampling_rate = 2000").encode()
        yield "inf value", txt.replace("\n0.0,", "\n0.0,1e999,", 1).encode()
        yield "10^5 columns", (",".join(["1"] * 100000) + "\n").encode()
    if fmt == "lvm":
        txt = raw.decode()
        yield "Samples says more", txt.replace("Samples\t400\t400", "Samples\t500\t500").encode()
        yield "complete last line, no end of line", txt.rstrip("\r\n").encode()


def classify(path, original, source_fmt):
    import vibmeasure as vm
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            rec = vm.read(path, fs=1000.0 if source_fmt in ("mat", "mat73") else None)
        except vm.ParameterError:
            return "named"
        except Exception as exc:  # noqa: BLE001 - counted as a defect
            return f"raw:{type(exc).__name__}"
    flagged = any(issubclass(w.category, vm.QualityWarning) for w in caught)
    same = rec.data.shape == original.shape and np.array_equal(rec.data, original)
    if source_fmt == "h5":   # the lazy reader must agree with the eager one
        try:
            lazy = vm.open(path).load().data
        except vm.ParameterError:
            return "raw:open refused what read took"
        except Exception as exc:  # noqa: BLE001 - counted as a defect
            return f"raw:open {type(exc).__name__}"
        if not np.array_equal(lazy, rec.data):
            return "silent"
    return "exact" if same else "flagged" if flagged else "silent"


def _worker(jobs, results):
    for idx, path, fmt, original in iter(jobs.get, None):
        results.put((idx, classify(path, original, fmt)))


def run_cases(cases, timeout):
    """Run (path, fmt, original) cases in a worker; a dead or stuck worker is replaced."""
    outcomes = [None] * len(cases)
    i = 0
    ctx = mp.get_context("fork")
    while i < len(cases):
        jobs, results = ctx.Queue(), ctx.Queue()
        proc = ctx.Process(target=_worker, args=(jobs, results), daemon=True)
        proc.start()
        for k in range(i, len(cases)):
            jobs.put((k, *cases[k]))
        jobs.put(None)
        while i < len(cases):
            t0 = time.monotonic()
            got = None
            while got is None and time.monotonic() - t0 < timeout:
                try:
                    got = results.get(timeout=0.2)
                except Exception:  # queue.Empty
                    if not proc.is_alive() and results.empty():
                        break
            if got is None:
                outcomes[i] = "hang" if proc.is_alive() else "crash"
                proc.kill()
                i += 1
                break
            outcomes[got[0]] = got[1]
            i = got[0] + 1
        proc.join(timeout=1)
    return outcomes


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--flips", type=int, default=200, help="flipped-byte cases per format (default 200)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds per case before it counts as a hang")
    args = ap.parse_args()
    rng = random.Random(args.seed)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        bases = base_files(folder)
        print(f"{'format':8s} {'cases':>6s} " + " ".join(f"{o:>8s}" for o in OUTCOMES))
        defects = []
        for fmt, (path, original) in bases.items():
            raw = Path(path).read_bytes()
            cases, labels = [], []
            for j, (label, blob) in enumerate(mutations(raw, fmt, args.flips, rng)):
                p = folder / f"{fmt}_{j}{Path(path).suffix}"
                p.write_bytes(blob)
                cases.append((p, fmt, original))
                labels.append(label)
            outcomes = run_cases(cases, args.timeout)
            count = Counter(o.split(":")[0] for o in outcomes)
            print(f"{fmt:8s} {len(cases):>6d} " + " ".join(f"{count.get(o, 0):>8d}" for o in OUTCOMES), flush=True)
            defects += [(fmt, lab, o) for lab, o in zip(labels, outcomes) if o.split(":")[0] in
                        ("raw", "silent", "crash", "hang")]
        if defects:
            print("\nnot named (format, mutation, outcome); a 'silent' flip in mat, mat73, lvm or uff changed a sample")
            print("value in a format that carries no checksum: no reader can tell it from a real value")
            for d, n in Counter(defects).most_common(30):
                print(f"  {n:4d} x {d}")
        else:
            print("\nno raw exception, silent change, crash or hang")


if __name__ == "__main__":
    main()
