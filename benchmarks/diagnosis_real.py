"""Machine diagnosis on real bearing recordings: every record of ../shared/data/cwru_fe, mfpt and cwru
through vm.diagnose, and beside it (same process, same records) a plain textbook reference: the
squared-envelope spectrum (SES) after a fixed 2-5 kHz band-pass of the fault-side channel, with the
same family scoring (comb of harmonics 1-3 at a common slip within +-2 %, capped line ratios) and no
pre-whitening, band selection, line ownership or channel fusion.

Prints both confusion matrices (true x predicted), correct / none / wrong counts, median time per
record and the records vm.diagnose gets wrong or leaves at "none" with their strongest candidate; then
every CWRU record read with the other end's bearing declared (bearing calls there are false calls).

Targets (issue 9): >= 40 of the 53 fault records of cwru_fe + mfpt right with <= 2 wrong calls;
every inner-race record right; every outer-race record whose BPFO comb stands >= 10 dB above the floor
in the pre-whitened SES right. That comb height is measured here on its own terms (``bpfo_comb_db``:
cepstral pre-whitening of the fault-side channel, SES of the whole band, mean height of BPFO x 1-3 at
the best common slip within +-2 % over the local median), not by vm.diagnose's own test.

    python benchmarks/diagnosis_real.py [--fault-channel-only] [--upsample N]

``--upsample N`` resamples every record to N times its rate first (scipy.signal.resample_poly, Kaiser
beta 10): the band above the old Nyquist is then a filter's stop band, which the diagnosis must leave
out (the answers should be those at the recorded rate).
"""

import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import scipy.io as sio
from scipy import fft as sfft

import vibmeasure as vm
from vibmeasure.monitor.bearing import ALPHA, FAMILIES
from vibmeasure.monitor.bearing.families import _family
from vibmeasure.monitor.bearing.spectra import _SES, _floor_ratio
from vibmeasure.signal.kurtogram import ses_power

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
CLASSES = ["bearing_outer_race", "bearing_inner_race", "bearing_ball", "other", "none"]
SHORT = {"bearing_outer_race": "outer", "bearing_inner_race": "inner", "bearing_ball": "ball", "other": "other",
         "none": "none"}


def scored(top: str) -> str:
    """The class an answer scores as: a bearing family, "none", or "other" (a shaft-order or gear fault
    named on a record whose seeded fault is a bearing's: a wrong fault named, counted with the wrong);
    "undetermined" (no fault named, a fault the more likely) scores as "none": nothing wrong is named."""
    return "none" if top == "undetermined" else top if top in CLASSES else "other"
MFPT_BEARING = vm.BEARINGS["MFPT"]


def records():
    """(set, name, record, rpm, bearing, truth, fault-side channel) for every development record."""
    truth_of = {"I": "bearing_inner_race", "O": "bearing_outer_race", "B": "bearing_ball", "N": "none"}
    for f in sorted((DATA / "cwru_fe").glob("*.mat")):
        rec = vm.read(f, fs=12000, unit="g")
        fe = next(n for n in rec.names if n.endswith("_FE_time"))
        yield "cwru_fe", f.name, rec, rec.meta["rpm"], "6203-2RS", truth_of[f.name[0]], fe
    for f in sorted((DATA / "mfpt").glob("*.mat")):
        rate = float(sio.loadmat(f, squeeze_me=True)["bearing"]["rate"].item())
        rec = vm.read(f, channels=["bearing.gs"], unit="g")
        yield "mfpt", f.name, rec, 60 * rate, MFPT_BEARING, truth_of[f.name[0]], "bearing.gs"
    for f in sorted((DATA / "cwru").glob("*.mat")):
        rec = vm.read(f, fs=12000, unit="g")
        de = next(n for n in rec.names if n.endswith("_DE_time"))
        yield "cwru", f.name, rec, rec.meta["rpm"], "6205-2RS", truth_of[f.name[0]], de


def reference(rec, rpm, bearing, channel):
    """Textbook SES: fixed 2-5 kHz band of the fault-side channel, family scoring without whitening."""
    x = rec.channel(channel).astype(float)
    f1 = rpm / 60
    b = vm.models.bearing.bearing_from(bearing)
    freqs = b.frequencies(f1)
    X = sfft.rfft(x - x.mean())
    f_need = 5 * max(freqs["BPFI"] + f1, freqs["2xBSF"] + freqs["FTF"])
    freq, amp, f_valid = ses_power(X, x.size, rec.fs, (2000.0, min(5000.0, 0.45 * rec.fs)), f_need)
    df = freq[1]
    ses = _SES(channel, "raw 2-5 kHz", (2000.0, 5000.0), freq, amp,
               _floor_ratio(amp, df, max(5.0, 0.25 * f1)), min(freq.size, int(f_valid / df)))
    best = None
    for name in FAMILIES:
        res = _family(ses, name, freqs, f1)
        if res and res["n_lines"] >= 2 and res["logp"] < np.log(ALPHA) and (best is None or res["logp"] < best[1]):
            best = (name, res["logp"])
    return best[0] if best else "none"


def bpfo_comb_db(rec, rpm, bearing, channel):
    """Height (dB) of the BPFO comb in the cepstrally pre-whitened SES of the fault-side channel: the
    mean over harmonics 1-3 of the line's power over the local median of the SES (+-5 Hz, as a mean:
    median / ln 2), at the common slip within +-2 % that maximises it."""
    from scipy.ndimage import median_filter
    from scipy.signal import hilbert
    x = rec.channel(channel).astype(float)
    X = sfft.rfft(x - x.mean())
    xw = sfft.irfft(X / np.maximum(np.abs(X), 1e-300), n=x.size)   # cepstral pre-whitening: unit magnitude
    env2 = np.abs(hilbert(xw)) ** 2
    P = np.abs(sfft.rfft(env2 - env2.mean())) ** 2
    df = rec.fs / x.size
    w = int(round(5.0 / df))
    floor = median_filter(P, size=2 * w + 1, mode="reflect") / np.log(2.0)
    ratio = P / np.maximum(floor, 1e-300)
    bpfo = vm.models.bearing.bearing_from(bearing).frequencies(rpm / 60)["BPFO"]
    best = 0.0
    for s in np.linspace(-0.02, 0.02, 81):
        h = [ratio[int(round(k * bpfo * (1 + s) / df)) - 1: int(round(k * bpfo * (1 + s) / df)) + 2].max()
             for k in (1, 2, 3)]
        best = max(best, float(np.mean(h)))
    return 10 * np.log10(best)


def confusion(rows, key):
    m = {t: dict.fromkeys(CLASSES, 0) for t in CLASSES}
    for r in rows:
        m[r["truth"]][r[key]] += 1
    return m


def show(title, rows, key):
    m = confusion(rows, key)
    faults = [r for r in rows if r["truth"] != "none"]
    right = sum(r[key] == r["truth"] for r in faults)
    none = sum(r[key] == "none" for r in faults)
    wrong = len(faults) - right - none
    other = sum(r[key] == "other" for r in faults)
    false_alarm = sum(r[key] != "none" for r in rows if r["truth"] == "none")
    print(f"\n{title}: {right} right / {none} none / {wrong} wrong of {len(faults)} fault records"
          f"{f' ({other} of the wrong name a shaft-order or gear fault)' if other else ''}; "
          f"false alarms on healthy records {false_alarm}")
    print(f"{'truth / predicted':>18} " + " ".join(f"{SHORT[c]:>6}" for c in CLASSES))
    for t in CLASSES:
        if sum(m[t].values()):
            print(f"{SHORT[t]:>18} " + " ".join(f"{m[t][c]:>6}" for c in CLASSES))
    return right, none, wrong


def upsampled(rec, n):
    """The record at n times its rate (a polyphase filter with a Kaiser window, beta 10)."""
    from scipy.signal import resample_poly
    return vm.Record.from_array(resample_poly(rec.data, n, 1, axis=1, window=("kaiser", 10.0)), fs=rec.fs * n,
                                names=list(rec.names), unit="g")


def main(fault_channel_only=False, upsample=1):
    warnings.simplefilter("ignore", vm.QualityWarning)
    rows = []
    for dset, name, rec, rpm, bearing, truth, channel in records():
        if upsample > 1:
            rec = upsampled(rec, upsample)
        t0 = time.perf_counter()
        d = vm.diagnose(rec, rpm=rpm, bearing=bearing, channel=channel,
                        channels=[channel] if fault_channel_only else None)
        dt = time.perf_counter() - t0
        t1 = time.perf_counter()
        ref = reference(rec, rpm, bearing, channel)
        dt_ref = time.perf_counter() - t1
        top = scored(d.top)
        comb = bpfo_comb_db(rec, rpm, bearing, channel) if truth == "bearing_outer_race" else None
        rows.append({"set": dset, "name": name, "truth": truth, "vm": top, "raw_top": d.top, "ref": ref, "t": dt,
                     "bpfo_db": comb,
                     "t_ref": dt_ref, "conf": d.confidence if top != "none" else d.p_healthy, "reason": d.reason, "channel": d.channel,
                     "n_ch": rec.n_channels})
        print(f"  {dset:8s} {name:28s} truth {SHORT[truth]:5s}  vibmeasure {SHORT[top]:5s} ({d.confidence:.2f}, "
              f"{d.channel})  reference {SHORT[ref]:5s}  {dt:.2f} s", flush=True)
    dev = [r for r in rows if r["set"] in ("cwru_fe", "mfpt")]
    print("\n=== development set: cwru_fe (45) + mfpt (8) ===")
    r_vm = show("vm.diagnose", dev, "vm")
    r_ref = show("reference (fixed 2-5 kHz SES)", dev, "ref")
    inner = [r for r in dev if r["truth"] == "bearing_inner_race"]
    print(f"\ninner-race records right: {sum(r['vm'] == r['truth'] for r in inner)} of {len(inner)} "
          f"(reference {sum(r['ref'] == r['truth'] for r in inner)})")
    print(f"targets: >= 40 right (got {r_vm[0]}), <= 2 wrong (got {r_vm[2]}); reference {r_ref[0]} right, "
          f"{r_ref[2]} wrong")
    outer = [r for r in dev if r["truth"] == "bearing_outer_race"]
    strong = [r for r in outer if r["bpfo_db"] >= 10.0]
    print(f"outer-race records whose BPFO comb stands >= 10 dB in the pre-whitened SES: {len(strong)} of "
          f"{len(outer)}; right {sum(r['vm'] == r['truth'] for r in strong)} of {len(strong)} (target: all)")
    for r in sorted(outer, key=lambda r: -r["bpfo_db"]):
        print(f"    {r['name']:28s} BPFO comb {r['bpfo_db']:5.1f} dB  vibmeasure {SHORT[r['vm']]}")
    # the confidence map was learnt on synthetic machines: how it reads on real ones (every record)
    print("\nconfidence on real records (all 57; the map was learnt on synthetic machines):")
    print(f"    {'answer':>8} {'confidence':>12} {'answers':>8} {'right':>8} {'mean':>8}")
    # a fault named is right with its confidence; an answer naming none is right (healthy) with p_healthy
    for kind, sel in (("fault", [r for r in rows if r["vm"] != "none"]),
                      ("none", [r for r in rows if r["vm"] == "none"])):
        for lo, hi in ((0.0, 0.5), (0.5, 0.9), (0.9, 0.99), (0.99, 1.01)):
            b = [r for r in sel if lo <= r["conf"] < hi]
            if b:
                print(f"    {kind:>8} {lo:>5.2f}-{min(hi, 1):<5.2f} {len(b):>8} "
                      f"{np.mean([r['vm'] == r['truth'] for r in b]):>8.2f} {np.mean([r['conf'] for r in b]):>8.2f}")
    print("\n=== cwru drive-end records ===")
    show("vm.diagnose", [r for r in rows if r["set"] == "cwru"], "vm")
    show("reference", [r for r in rows if r["set"] == "cwru"], "ref")
    for label, sel in ((f"{12 * upsample:g} kHz, 10 s, 3 channels", [r for r in rows if r["set"] == "cwru_fe"]),
                       (f"MFPT {48.828 * upsample:.1f} kHz, 3 s, 1 channel", [r for r in rows if r["set"] == "mfpt"])):
        print(f"\nmedian time per record ({label}): vibmeasure {statistics.median(r['t'] for r in sel):.3f} s, "
              f"reference {statistics.median(r['t_ref'] for r in sel):.3f} s")
    print("\nnot right (vibmeasure):")
    for r in rows:
        if r["vm"] != r["truth"]:
            print(f"  {r['name']:28s} truth {SHORT[r['truth']]:5s} got {r['raw_top']:20s} {r['reason'][:160]}")
    if upsample == 1 and not fault_channel_only:
        other_end()


def other_end():
    """Every CWRU record (fan-end faults and the drive-end records) read with the bearing at the other end
    of the motor declared, every channel: the seeded fault is not in that bearing, so a bearing call
    there is a false call unless that bearing was damaged too (no record says so). A measure of false
    calls on real spectra, with their lines of another bearing."""
    other = {"6203-2RS": "6205-2RS", "6205-2RS": "6203-2RS"}
    calls = []
    n = 0
    for dset, name, rec, rpm, bearing, truth, channel in records():
        if dset == "mfpt":
            continue
        n += 1
        d = vm.diagnose(rec, rpm=rpm, bearing=other[bearing], channel=channel)
        if d.top.startswith("bearing_"):
            calls.append(f"{name} ({other[bearing]}: {SHORT[d.top]}, {d.confidence:.2f})")
    print(f"\nCWRU records read with the other end's bearing declared (healthy there): {len(calls)} bearing "
          f"calls of {n} records")
    for c in calls:
        print(f"    {c}")


if __name__ == "__main__":
    up = int(sys.argv[sys.argv.index("--upsample") + 1]) if "--upsample" in sys.argv else 1
    main(fault_channel_only="--fault-channel-only" in sys.argv, upsample=up)
