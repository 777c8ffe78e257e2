"""Pre-whitening: cepstral (flat magnitude), AR (innovations back), shaft-synchronous removal (exact on
harmonics of the shaft), discrete-line editing; bad input."""
import numpy as np
import pytest
from scipy import signal as sg

import vibmeasure as vm
from vibmeasure.signal.whiten import edit_lines


def test_cepstral_prewhitening_flattens_the_magnitude(rng):
    # a resonance plus strong tones: after cepstral pre-whitening every FFT bin has the same magnitude
    fs, n = 10000.0, 20000
    t = np.arange(n) / fs
    b, a = sg.butter(2, (2000, 2500), btype="bandpass", fs=fs)
    x = sg.lfilter(b, a, rng.normal(size=n)) + 3 * np.sin(2 * np.pi * 50 * t) + np.sin(2 * np.pi * 733.3 * t)
    y = vm.prewhiten(vm.Record.from_array(x, fs=fs), method="cepstral")
    mag = np.abs(np.fft.rfft(y.data[0]))[1:-1]
    assert np.ptp(mag) / np.mean(mag) < 1e-8  # flat to round-off: only the phase is left
    assert y.names == ["ch0.white"] and "prewhiten" in y.history[-1]


def test_ar_whitening_returns_the_innovations(rng):
    # an AR(2) process driven by white noise: the prediction error of the fitted model is that noise
    n = 40000
    e = rng.normal(size=n)
    x = sg.lfilter([1.0], [1.0, -1.6, 0.8], e)
    y = vm.prewhiten(vm.Record.from_array(x, fs=1000.0), method="ar", order=2).data[0]
    # correlation with the true innovations (the first samples are the filter's start-up)
    assert np.corrcoef(y[10:], e[10:])[0, 1] > 0.999
    r = np.correlate(y[10:], y[10:], "full")[y.size - 10 - 1:][:6] / np.dot(y[10:], y[10:])
    assert np.max(np.abs(r[1:])) < 0.02  # white: sample autocorrelation within ~4/sqrt(n)


def test_remove_synchronous_takes_out_every_shaft_harmonic(rng):
    # 1X..8X of a 29.95 Hz shaft on top of noise: what is left is the noise (TSA error ~ 1/sqrt(revs))
    fs, f1 = 12000.0, 29.95
    t = np.arange(int(10 * fs)) / fs
    sync = sum(a * np.sin(2 * np.pi * k * f1 * t + k) for k, a in enumerate([1, .5, .4, .3, .3, .2, .2, .1], 1))
    noise = 0.05 * rng.normal(size=t.size)
    rec = vm.Record.from_array(sync + noise, fs=fs, quantity="acceleration", unit="g")
    left = vm.remove_synchronous(rec, shaft_hz=f1).data[0]
    # residual synchronous part: below 1/sqrt(299 revolutions) of the noise plus the binning error
    assert np.std(left - noise) < 0.2 * np.std(noise)
    assert np.std(left) == pytest.approx(np.std(noise), rel=0.05)


def test_edit_lines_keeps_random_content_and_cuts_tones(rng):
    fs, n = 5000.0, 50000
    t = np.arange(n) / fs
    noise = rng.normal(size=n)
    y = edit_lines(noise + 20 * np.sin(2 * np.pi * 123.4 * t))
    P = np.abs(np.fft.rfft(y)) ** 2
    k = int(round(123.4 * n / fs))
    assert P[k - 2: k + 3].max() < 20 * np.median(P)   # the tone is cut to the local level
    assert np.std(y) == pytest.approx(np.std(noise), rel=0.02)


def test_bad_input():
    rec = vm.Record.from_array(np.random.default_rng(0).normal(size=5000), fs=1000.0)
    with pytest.raises(vm.ParameterError, match="method="):
        vm.prewhiten(rec, method="lpc")
    with pytest.raises(vm.ParameterError, match="order="):
        vm.prewhiten(rec, method="ar", order=0)
    with pytest.raises(vm.ParameterError, match="revolutions"):
        vm.remove_synchronous(rec, shaft_hz=1.0)
    with pytest.raises(vm.ParameterError, match="shaft_hz"):
        vm.remove_synchronous(rec, shaft_hz=-5.0)
    with pytest.raises(vm.ParameterError, match="constant"):
        vm.prewhiten(vm.Record.from_array(np.ones(1000), fs=1000.0))


# --- the band a record measures -----------------------------------------------------------------------

def _lowpassed(fc_frac, fs=12000.0, n=2 ** 17, seed=0, floor_db=-100.0):
    """White noise through an 8th-order Butterworth low-pass run forwards and backwards (sosfiltfilt:
    |H|^4), plus a converter floor floor_db below the signal."""
    from scipy.signal import butter, sosfiltfilt
    rng = np.random.default_rng(seed)
    y = sosfiltfilt(butter(8, fc_frac * fs / 2, fs=fs, output="sos"), rng.normal(size=n))
    return y + rng.normal(size=n) * y.std() * 10 ** (floor_db / 20), fs


def test_a_record_with_content_up_to_nyquist_keeps_its_whole_band():
    from vibmeasure.signal.whiten import measured_top
    for seed in range(5):
        x = np.random.default_rng(seed).normal(size=2 ** 17)
        assert measured_top(np.fft.rfft(x), 12000.0, x.size) == 6000.0


@pytest.mark.parametrize("fc_frac", [0.25, 0.5, 0.8])
def test_the_measured_band_ends_where_the_anti_alias_filter_has_cut_25_db(fc_frac):
    # oracle: the digital filter's own response, run twice (|H|^4); the measured band ends where it
    # first falls DEAD_DB = 25 dB below the flat pass band; tolerance -2 %..+5 %: the levels are
    # bands of fs/1024 smoothed over 5, and the mean level under the cut takes in part of the
    # filter's own transition (measured: +0.2 % to +2.3 % over three seeds)
    from scipy.signal import butter, sosfreqz
    from vibmeasure.signal.whiten import DEAD_DB, measured_top
    x, fs = _lowpassed(fc_frac)
    top = measured_top(np.fft.rfft(x), fs, x.size)
    f, h = sosfreqz(butter(8, fc_frac * fs / 2, fs=fs, output="sos"), worN=2 ** 16, fs=fs)
    f_cut = f[np.argmax(40 * np.log10(np.maximum(np.abs(h), 1e-30)) < -DEAD_DB)]
    assert 0.98 * f_cut <= top <= 1.05 * f_cut


def test_a_lone_tone_in_the_stop_band_does_not_reopen_it():
    # a converter spur 20 dB above the pass band's spectral level, alone in the stop band: one band of
    # 512 is loud, its running median over 5 neighbours is not
    from vibmeasure.signal.whiten import measured_top
    x, fs = _lowpassed(0.4)
    t = np.arange(x.size) / fs
    clean = measured_top(np.fft.rfft(x), fs, x.size)
    spur = x + 0.05 * np.sin(2 * np.pi * 5000.0 * t)
    assert measured_top(np.fft.rfft(spur), fs, x.size) == pytest.approx(clean, abs=30.0)


def test_the_tapered_spectrum_is_taken_once_per_content():
    """The transient check and the bearing spectra share a channel's tapered spectrum: the same samples
    (another array holding them too) give the same read-only spectrum, equal to the rfft it stands for;
    samples changed in place give a new one, never the old."""
    from scipy import fft as sfft
    from scipy.signal.windows import tukey
    from vibmeasure.signal.whiten import tapered_spectrum
    x = np.random.default_rng(3).normal(size=4096)
    X = tapered_spectrum(x, 0.05)
    assert np.array_equal(X, sfft.rfft((x - x.mean()) * tukey(x.size, 0.05))) and not X.flags.writeable
    assert tapered_spectrum(x.copy(), 0.05) is X
    x[100] += 1.0
    Y = tapered_spectrum(x, 0.05)
    assert Y is not X and np.array_equal(Y, sfft.rfft((x - x.mean()) * tukey(x.size, 0.05)))
    assert tapered_spectrum(x, 0.1) is not Y   # another taper, another spectrum
