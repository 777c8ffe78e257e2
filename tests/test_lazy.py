"""Out-of-core records: vm.open over real HDF5 files, streamed spectra equal in-memory ones."""
import h5py
import numpy as np
import pytest

import vibmeasure as vm
import vibmeasure.signal.segments as spectral


def test_open_own_schema_and_stream_psd(tmp_path, rng, monkeypatch):
    rec = vm.Record(rng.normal(size=(2, 300_000)), fs=2048.0,
                    channels=[vm.Channel("a", "acceleration", "g"), vm.Channel("b", "acceleration", "g")])
    p = vm.write(tmp_path / "r.h5", rec)
    lazy = vm.open(p)
    assert (lazy.n_channels, lazy.n_samples, lazy.fs, lazy.names) == (2, 300_000, 2048.0, ["a", "b"])
    monkeypatch.setattr(spectral, "READ_SAMPLES", 50_000)  # force many blocks (segments straddle reads)
    seen = []
    streamed = vm.psd(lazy, nperseg=4096, progress=seen.append)
    np.testing.assert_allclose(streamed.values, vm.psd(rec, nperseg=4096).values, rtol=1e-12)
    assert len(seen) > 5 and seen[-1] == 1.0
    amp = vm.amplitude_spectrum(lazy, channels=["b"])
    assert amp.params["nperseg"] == 65536 and amp.channels == ("b",)
    assert lazy.load() == vm.read(p).replace(history=lazy.load().history)


def test_read_into_a_buffer_equals_a_fresh_read(tmp_path, rng):
    # the streamed PSD reads a file's blocks into two reused buffers (HDF5 converts float32 -> float64)
    p = tmp_path / "f32.h5"
    x = rng.normal(size=(3, 10_000)).astype(np.float32)
    with h5py.File(p, "w") as f:
        f.create_dataset("x", data=x, chunks=(3, 4096))
    lazy = vm.open(p, dataset="x", fs=1000.0)
    out = np.full((3, 2500), np.nan)
    assert lazy.read(1000, 3500, out=out) is out
    np.testing.assert_array_equal(out, lazy.read(1000, 3500))
    np.testing.assert_array_equal(out, x[:, 1000:3500].astype(float))
    with pytest.raises(vm.ParameterError, match="out must be a C-contiguous float64 array of shape \\(3, 2500\\)"):
        lazy.read(1000, 3500, out=np.empty((3, 2400)))


def test_a_block_that_fails_in_the_read_ahead_is_a_named_error(tmp_path, rng, monkeypatch):
    # a compressed file damaged in its middle: the block the I/O thread reads ahead fails to decode,
    # and the PSD raises the reader's ParameterError (range named), not a thread's traceback
    p = tmp_path / "gz.h5"
    with h5py.File(p, "w") as f:
        f.create_dataset("x", data=rng.normal(size=400_000).astype(np.float32), chunks=(20_000,),
                         compression="gzip")
    size = p.stat().st_size
    with open(p, "r+b") as f:
        f.seek(int(size * 0.7))
        f.write(b"\x00garbage" * 200)
    monkeypatch.setattr(spectral, "READ_SAMPLES", 50_000)   # many blocks: the damage is read ahead
    with pytest.raises(vm.ParameterError, match=r"samples \d+\.\.\d+ are unreadable"):
        vm.psd(vm.open(p, dataset="x", fs=1000.0), nperseg=4096)


def test_open_bare_float32_dataset(tmp_path):
    p = tmp_path / "daq.h5"
    t = np.arange(200_000) / 10_000.0
    with h5py.File(p, "w") as f:
        f.create_dataset("acq/ch1", data=(0.5 * np.sin(2 * np.pi * 250 * t)).astype(np.float32), chunks=(65536,))
    with pytest.raises(vm.ParameterError, match="fs .sampling rate in Hz. is required"):
        vm.open(p, dataset="acq/ch1")
    lazy = vm.open(p, dataset="acq/ch1", fs=10_000.0, unit="g")
    s = vm.amplitude_spectrum(lazy, nperseg=10_000, window="flattop")
    assert s.values[0].max() == pytest.approx(0.5, rel=1e-6) and s.unit == "g"


def test_open_errors(tmp_path):
    with pytest.raises(vm.ParameterError, match="does not exist"):
        vm.open(tmp_path / "no.h5")
    (tmp_path / "x.csv").write_text("1\n")
    with pytest.raises(vm.ParameterError, match="reads HDF5"):
        vm.open(tmp_path / "x.csv")
    bad = tmp_path / "bad.h5"
    bad.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 50)
    with pytest.raises(vm.ParameterError, match="unreadable"):
        vm.open(bad)


def test_envelope_spectrum_of_a_lazy_record_is_streamed_and_exact(tmp_path):
    # x = A (1 + m cos 2 pi fm t) cos 2 pi fc t: the SES line at fm is 2 m A^2 (segments of 20000 put fm on a bin);
    # the record is never loaded whole (segments of nperseg samples, half overlap)
    import vibmeasure as vm
    fs, n, A, m = 10000.0, 400_000, 1.5, 0.4
    t = np.arange(n) / fs
    x = A * (1 + m * np.cos(2 * np.pi * 50 * t)) * np.cos(2 * np.pi * 2500 * t)
    p = vm.write(tmp_path / "am.h5", vm.Record.from_array(x, fs=fs))
    seen = []
    s = vm.envelope_spectrum(vm.open(p), band=(2000, 3000), nperseg=20000, progress=seen.append)
    assert s.values[0][np.argmin(np.abs(s.freq - 50))] == pytest.approx(2 * m * A ** 2, rel=1e-6)
    assert s.params["streamed"] and s.params["averages"] == 39 and seen[-1] == 1.0
    mem = vm.envelope_spectrum(vm.read(p), band=(2000, 3000), nperseg=20000)   # the in-memory path agrees on the line
    assert mem.values[0][np.argmin(np.abs(mem.freq - 50))] == pytest.approx(2 * m * A ** 2, rel=1e-3)


def test_streamed_envelope_refuses_a_bad_nperseg(tmp_path):
    import vibmeasure as vm
    p = vm.write(tmp_path / "r.h5", vm.Record.from_array(np.sin(np.arange(5000.0)), fs=1000.0))
    for bad, match in (("x", "integer"), (100, "at least 256")):
        with pytest.raises(vm.ParameterError, match=match):
            vm.envelope_spectrum(vm.open(p), band=(100, 300), nperseg=bad)


def _crafted(path, *, data=None, names=("a", "b"), fs=100.0, meta="{}", drop=()):
    """A record file in vibmeasure's schema, unsealed, with one part wrong."""
    import h5py
    data = np.zeros((2, 100)) if data is None else data
    with h5py.File(path, "w") as f:
        f.attrs["vibmeasure_schema"] = "vibmeasure.record"
        f.attrs["schema_version"] = 1
        f.attrs["meta"] = meta
        d = f.create_dataset("data", data=data)
        attrs = {"fs": fs, "t0": 0.0, "channel_names": list(names), "channel_quantities": ["unknown"] * len(names),
                 "channel_units": [""] * len(names), "channel_locations": [""] * len(names)}
        for k, v in attrs.items():
            if k not in drop:
                d.attrs[k] = v
    return path


@pytest.mark.parametrize("kw,rule", [
    ({"drop": ("channel_names",)}, "damaged"),
    ({"fs": "abc"}, "not a number"),
    ({"fs": -5.0}, "must be > 0"),
    ({"meta": "{not json"}, "damaged"),
    ({"meta": "[1, 2]"}, "not a mapping"),
    ({"data": np.zeros((2, 100)) + 1j}, "complex"),
    ({"data": np.zeros((2, 0))}, "at least 2"),
    ({"names": ("a", "b", "c")}, "3 channel descriptions"),
])
def test_the_lazy_path_is_as_strict_as_the_eager_one(tmp_path, kw, rule):
    """Issue 48: each crafted record file ends in a ParameterError naming the rule, from vm.open as from vm.read."""
    p = _crafted(tmp_path / "bad.h5", **kw)
    with pytest.raises(vm.ParameterError, match=rule):
        vm.open(p)
    with pytest.raises(vm.ParameterError):
        vm.read(p)


def test_the_lazy_path_refuses_a_record_without_data(tmp_path):
    import h5py
    p = tmp_path / "nodata.h5"
    with h5py.File(p, "w") as f:
        f.attrs["vibmeasure_schema"] = "vibmeasure.record"
    for reader in (vm.open, vm.read):
        with pytest.raises(vm.ParameterError, match="data"):
            reader(p)
