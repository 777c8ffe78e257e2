"""The main job a newcomer runs: synthesised inputs analysed into a report and a store."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .html import report


def demo(out_dir="vibmeasure-demo", *, progress=None) -> dict:
    """The main job a newcomer runs: synthesise the demo inputs (if absent) with vm.synth, analyse
    them, write ``out_dir/report.html`` and ``out_dir/results.db`` (a Store with the fleet history).
    Returns a short summary (paths, key numbers, seconds). ``progress(message)`` follows the steps."""
    import time

    from .. import io, synth
    from ..monitor.batch import batch
    t0 = time.perf_counter()
    say = progress if callable(progress) else (lambda msg: None)
    out = Path(out_dir)
    inp = out / "inputs"
    inp.mkdir(parents=True, exist_ok=True)
    files = {"ringdown": inp / "ringdown_beam.h5", "hammer": inp / "hammer_test.h5", "machine": inp / "pump_bearing.h5"}
    if not files["ringdown"].exists():
        say("synthesising a ring-down (beam, 23.7 Hz, zeta 0.012, 40 dB)")
        io.write(files["ringdown"], synth.free_decay(fn=23.7, zeta=0.012, fs=2000.0, duration=8.0, snr_db=40,
                                                     amplitude=5e-4, seed=1, quantity="acceleration", unit="m/s^2"))
    if not files["hammer"].exists():
        say("synthesising a hammer test (3 modes, 2 outputs)")
        fs, n = 2048.0, 8192
        f = np.zeros(n)
        f[100:103] = np.sin(np.pi * (np.arange(3) + 0.5) / 3) * 300.0  # a 1.5 ms half-sine hit: flat to ~500 Hz
        resp = synth.modal_response(f, fs=fs, fn=[31.0, 87.0, 165.0], zeta=[0.02, 0.015, 0.01],
                                    shapes=[[1.0, 0.8, 0.5], [0.6, -0.7, 0.9]], quantity="acceleration")
        rng = np.random.default_rng(3)
        resp += 0.002 * np.abs(resp).max() * rng.standard_normal(resp.shape)
        from ..core.record import Channel, Record
        io.write(files["hammer"], Record(np.vstack([f + 0.05 * rng.standard_normal(n), resp]), fs,
                                         [Channel("hammer", "force", "N"), Channel("acc1", "acceleration", "m/s^2"),
                                          Channel("acc2", "acceleration", "m/s^2")]))
    if not files["machine"].exists():
        say("synthesising a pump with an outer-race bearing fault")
        io.write(files["machine"], synth.machine(fault="bearing_outer_race", rpm=1480.0, fs=12800.0, duration=2.0,
                                                 severity=0.6, seed=4))
    fleet_dir = inp / "fleet"
    if not (fleet_dir / "machines.csv").exists():
        say("synthesising a small fleet (4 assets, 20 weekly measurements)")
        synth.fleet(fleet_dir, n_measurements=20, fault_onset=10)
    store = out / "results.db"
    say("analysing the fleet into results.db")
    batch(task="diagnose+spectrum", store=store, manifest=fleet_dir / "machines.csv")
    batch(task="ringdown+compare", store=store, manifest=fleet_dir / "structures.csv")
    say("writing report.html")
    path = report([files["ringdown"], files["hammer"], files["machine"]], out / "report.html", store=store,
                  title="vibmeasure demo report", rpm=None, bearing="6205-2RS",
                  summary=["a ring-down of a beam (maximum-likelihood fn and zeta with their std)",
                           "a hammer test on a 3-mode structure (FRFs, stabilisation, modes)",
                           "a pump with an outer-race bearing defect (envelope analysis, ISO severity)",
                           "a fleet of 4 assets over 20 weeks (trends, limits, verdicts)"])
    return {"report": path, "store": store, "seconds": time.perf_counter() - t0,
            "size_bytes": path.stat().st_size}
