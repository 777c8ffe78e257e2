"""Spectra against closed forms (sine amplitude and RMS, Parseval, white-noise level) and scipy."""
import numpy as np
import pytest
import scipy.signal as sg

import vibmeasure as vm

FS = 1000.0


def sine(a=2.5, f=100.0, n=10000, fs=FS, unit="m/s^2", q="acceleration"):
    t = np.arange(n) / fs
    return vm.Record.from_array(a * np.sin(2 * np.pi * f * t + 0.3), fs=fs, quantity=q, unit=unit, name="acc")


@pytest.mark.parametrize("window", ["hann", "boxcar", "flattop", "hamming", ("kaiser", 8.0)])
def test_sine_on_bin_reads_its_amplitude(window):
    # 100 Hz in a 10 s record is exactly on a bin: the window correction 2/sum(w) is exact; what is
    # left is the leakage of the negative-frequency image 2000 bins away through the window's far
    # sidelobes (Kaiser 8: about 1e-8)
    s = vm.amplitude_spectrum(sine(), window=window)
    k = np.argmin(abs(s.freq - 100.0))
    assert s.values[0, k] == pytest.approx(2.5, rel=1e-7)
    rms = vm.amplitude_spectrum(sine(), window=window, scaling="rms").values[0, k]
    assert rms == pytest.approx(2.5 / np.sqrt(2), rel=1e-7)
    assert vm.amplitude_spectrum(sine(), window=window, scaling="peak-to-peak").values[0, k] == pytest.approx(5.0)
    assert s.unit == "m/s^2" and s.kind == "amplitude"


def test_flattop_reads_off_bin_amplitude_within_its_flatness():
    # flat-top's scalloping loss is below 0.02 dB anywhere between bins
    s = vm.amplitude_spectrum(sine(f=100.05), window="flattop")
    assert s.values[0].max() == pytest.approx(2.5, rel=2.5e-3)


def test_parseval_exact_for_one_rectangular_segment(rng):
    x = rng.normal(size=4096)
    r = vm.Record.from_array(x, fs=FS)
    p = vm.psd(r, nperseg=4096, window="boxcar", detrend=False)
    assert np.sum(p.values[0]) * p.df == pytest.approx(np.mean(x ** 2), rel=1e-12)


def test_white_noise_psd_level(rng):
    # density of white noise of variance s^2 is 2 s^2 / fs one-sided; 2^20 samples with 511
    # averages leave ~1 % scatter on the mean level over 2049 lines (much less): 1 %
    s = 0.3
    r = vm.Record.from_array(rng.normal(0, s, 2 ** 20), fs=FS, unit="g", quantity="acceleration")
    p = vm.psd(r, nperseg=4096)
    assert np.mean(p.values[0, 1:-1]) == pytest.approx(2 * s ** 2 / FS, rel=0.01)
    assert p.unit == "g^2/Hz"
    assert vm.band_rms(p, (0, FS / 2))[0] == pytest.approx(s, rel=0.01)


@pytest.mark.parametrize("kw", [dict(nperseg=4096), dict(nperseg=1000, noverlap=250, window="flattop"),
                                dict(nperseg=512, detrend="linear"), dict(nperseg=256, average="median"),
                                dict(nperseg=1024, nfft=4096, scaling="spectrum")])
def test_psd_equals_scipy_welch(rng, kw):
    x = rng.normal(size=(3, 50_000))
    ours = vm.psd(vm.Record(x, fs=FS), **kw)
    f, ref = sg.welch(x, fs=FS, **kw)
    np.testing.assert_allclose(ours.freq, f, rtol=1e-14)
    np.testing.assert_allclose(ours.values, ref, rtol=1e-10)


@pytest.mark.parametrize("nperseg,noverlap", [(4096, 2048), (4096, 3072), (4096, 0), (1000, 250), (777, 300)])
def test_psd_removes_large_offsets_like_welch(rng, monkeypatch, nperseg, noverlap):
    # Offsets far above the noise, in several read blocks (READ_SAMPLES made small) and both ways of
    # summing segments (parts of gcd(step, nperseg) samples; plain sums for 777/300). The mean is
    # taken out of the lines the window's transform touches after the FFT, from values ~offset x N:
    # cancellation leaves ~1e-12 of the line (welch subtracts before windowing): 1e-9
    import vibmeasure.signal.segments as sp
    monkeypatch.setattr(sp, "READ_SAMPLES", 30_000)
    x = rng.normal(size=(2, 100_003)) + np.array([[40.0], [-2.0e3]])
    ours = vm.psd(vm.Record(x, fs=FS), nperseg=nperseg, noverlap=noverlap)
    _, ref = sg.welch(x, fs=FS, nperseg=nperseg, noverlap=noverlap)
    np.testing.assert_allclose(ours.values, ref, rtol=1e-9)
    # left in, the -2000 offset would put lines 0-1 some 1e9 times above the noise level
    assert ours.values[1, :2].max() < 10 * ours.values[1, 5:].mean()


def test_psd_from_several_threads_at_once(rng):
    # each thread keeps its own work buffers between calls: concurrent calls must not share them
    from concurrent.futures import ThreadPoolExecutor
    recs = [vm.Record(rng.normal(size=2 ** 17) + k, fs=FS) for k in range(6)]
    alone = [vm.psd(r, nperseg=2048).values for r in recs]
    with ThreadPoolExecutor(3) as ex:
        for _ in range(3):
            together = list(ex.map(lambda r: vm.psd(r, nperseg=2048).values, recs))
            for a, b in zip(alone, together):
                # the two FFT threads share a call's batches differently from run to run, so the
                # sums add in another order: rounding only (1e-13); a shared buffer would be O(1)
                np.testing.assert_allclose(b, a, rtol=1e-13)


def test_work_buffers_kept_only_when_small():
    import vibmeasure.signal.segments as sp
    a = sp._scratch("probe", (16, 4096), np.float64)
    assert sp._scratch("probe", (16, 4096), np.float64) is a          # reused: no fresh pages per call
    big = (16, sp.SCRATCH_BYTES // 8)                                    # 16 x 4 MB: allocated per call
    assert sp._scratch("probe_big", big, np.float64) is not sp._scratch("probe_big", big, np.float64)


def test_csd_and_coherence_equal_scipy(rng):
    x = rng.normal(size=20_000)
    y = np.convolve(x, [0.5, 0.3, -0.2], mode="same") + 0.3 * rng.normal(size=x.size)
    r = vm.Record(np.vstack([x, y]), fs=FS, channels=[vm.Channel("f", "force", "N"), vm.Channel("a")])
    _, pxy = sg.csd(x, y, fs=FS, nperseg=512)
    _, cxy = sg.coherence(x, y, fs=FS, nperseg=512)
    np.testing.assert_allclose(vm.csd(r, "f", "a", nperseg=512).values[0], pxy, rtol=1e-10, atol=1e-16)
    np.testing.assert_allclose(vm.coherence(r, "f", "a", nperseg=512).values[0], cxy, rtol=1e-10, atol=1e-14)


def test_spectrogram_tracks_a_chirp():
    t = np.arange(20000) / FS
    x = np.sin(2 * np.pi * (50 * t + 5 * t ** 2))  # 50 Hz rising 10 Hz per second
    sp = vm.spectrogram(vm.Record.from_array(x, fs=FS), nperseg=1000, noverlap=0)
    peak_f = sp.freq[np.argmax(sp.values[0], axis=0)]
    np.testing.assert_allclose(peak_f, 50 + 10 * sp.times, atol=1.0)  # 1 Hz lines


def test_band_rms_of_two_tones():
    t = np.arange(100_000) / FS
    x = 3.0 * np.sin(2 * np.pi * 50 * t) + 4.0 * np.sin(2 * np.pi * 200 * t)
    r = vm.Record.from_array(x, fs=FS)
    assert vm.band_rms(r, (10, 100), nperseg=4096)[0] == pytest.approx(3 / np.sqrt(2), rel=1e-3)
    assert vm.band_rms(r, (0, 500), nperseg=4096)[0] == pytest.approx(5 / np.sqrt(2), rel=1e-3)


def test_third_octave_bands_hold_the_tone():
    t = np.arange(200_000) / 4000.0
    r = vm.Record.from_array(2.0 * np.sin(2 * np.pi * 1000 * t), fs=4000.0)
    tab = vm.octave_bands(r, fraction=3, nperseg=8192)
    row = tab.loc[(tab.center_hz - 1000).abs().idxmin()]
    assert row["center_hz"] == pytest.approx(1000.0)
    assert row["rms_ch0"] == pytest.approx(np.sqrt(2), rel=1e-3)
    assert tab["rms_ch0"].drop(index=row.name).max() < 1e-3
    oct_ = vm.octave_bands(r, fraction=1, nperseg=8192)
    assert np.allclose(oct_.upper_hz / oct_.lower_hz, 10 ** 0.3)


def test_multichannel_and_channel_selection(rng):
    r = vm.Record(rng.normal(size=(8, 8192)), fs=FS)
    p = vm.psd(r, nperseg=1024, channels=["ch3", "ch5"])
    assert p.channels == ("ch3", "ch5") and p.values.shape == (2, 513)
    with pytest.raises(vm.ParameterError, match="'ch9' is not in this record"):
        vm.psd(r, channels=["ch9"])


@pytest.mark.parametrize("kw,match", [
    (dict(nperseg=20000), "nperseg=20000 exceeds the record length 10000"),
    (dict(nperseg=256, noverlap=256), "noverlap=256 must be"),
    (dict(window="bogus"), "window='bogus' is not a known window"),
    (dict(nperseg=256, nfft=100), "nfft=100 must be"),
    (dict(detrend="cubic"), "detrend="),
    (dict(average="mode"), "average="),
])
def test_bad_parameters(kw, match):
    with pytest.raises(vm.ParameterError, match=match):
        vm.psd(sine(), **kw)


def test_nan_and_band_rejected():
    x = np.sin(np.arange(1000.0))
    x[500] = np.nan
    with pytest.raises(vm.ParameterError, match="NaN/inf at sample 500"):
        vm.psd(vm.Record.from_array(x, fs=FS), nperseg=256)
    with pytest.raises(vm.ParameterError, match="band="):
        vm.band_rms(sine(), (100, 900))
    with pytest.raises(vm.ParameterError, match="at least 2 averages"):
        r = vm.Record(np.vstack([np.sin(np.arange(512.0)), np.cos(np.arange(512.0))]), fs=FS)
        vm.coherence(r, 0, 1, nperseg=512)
