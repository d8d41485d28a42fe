"""microcobot.dsp against scipy.signal (an independent implementation of the same definitions).

Tolerances: both sides compute in IEEE double with different operation orders, so equal formulas
agree to a few ulps of the largest intermediate. Filter design (poles from sin/cos, bilinear
transform) is compared at 1e-10 relative; filtering at 1e-12 of the signal's scale (TDF-II, the
same recursion as scipy); Welch spectra at 1e-9 relative (FFT round-off, pocketfft vs Eigen's
kissfft, on values spanning ~10 decades, hence an absolute floor at 1e-12 of the peak).
"""

import numpy as np
import pytest
import scipy.signal as sig

from microcobot import dsp


@pytest.mark.parametrize("order", [1, 2, 4, 7])
@pytest.mark.parametrize("btype", ["low", "high"])
def test_butter_equals_scipy(order, btype):
    ours = dsp.butter(order, 150.0, btype=btype, fs=10000.0)
    ref = sig.butter(order, 150.0, btype=btype, fs=10000.0, output="sos")
    assert ours.shape == ref.shape
    np.testing.assert_allclose(ours, ref, rtol=1e-10, atol=1e-14)
    # Without fs, Wn is a fraction of Nyquist (scipy's convention).
    np.testing.assert_allclose(dsp.butter(order, 0.3, btype), sig.butter(order, 0.3, btype, output="sos"),
                               rtol=1e-10, atol=1e-14)


def test_linkwitz_riley_is_butterworth_squared_and_lr4_crossover_is_allpass():
    fs, fc = 10000.0, 200.0
    lr4 = dsp.linkwitz_riley(4, fc, "low", fs=fs)
    b2 = sig.butter(2, fc, fs=fs, output="sos")
    np.testing.assert_allclose(lr4, np.vstack([b2, b2]), rtol=1e-10, atol=1e-14)
    low, high = dsp.crossover(4, fc, fs=fs)
    f = np.geomspace(1.0, 4900.0, 200)
    _, hl = sig.sosfreqz(low, worN=f, fs=fs)
    _, hh = sig.sosfreqz(high, worN=f, fs=fs)
    # Thesis §3.3: the LR4 pair sums to an all-pass, |L + H| = 1, and each is -6 dB at fc.
    np.testing.assert_allclose(np.abs(hl + hh), 1.0, atol=1e-9)
    _, hc = sig.sosfreqz(low, worN=[fc], fs=fs)
    assert 20 * np.log10(abs(hc[0])) == pytest.approx(-6.02, abs=0.01)
    # Our sosfreqz gives scipy's numbers.
    ff, h = dsp.sosfreqz(low, worN=f, fs=fs)
    np.testing.assert_allclose(h, hl, rtol=1e-10, atol=1e-14)


def test_sosfilt_equals_scipy():
    rng = np.random.default_rng(3)
    x = rng.standard_normal(20000)
    for sos in (sig.butter(6, 40.0, fs=10000.0, output="sos"), sig.butter(1, 0.2, "high", output="sos")):
        y = dsp.sosfilt(sos, x)
        np.testing.assert_allclose(y, sig.sosfilt(sos, x), rtol=0, atol=1e-12 * np.abs(x).max())


@pytest.mark.parametrize("nperseg,noverlap,nfft", [(256, None, None), (1000, 300, 2048), (64, 0, None)])
def test_welch_equals_scipy(nperseg, noverlap, nfft):
    rng = np.random.default_rng(7)
    t = np.arange(30000) / 25000.0
    x = np.sin(2 * np.pi * 1633.0 * t) + 0.1 * rng.standard_normal(t.size)
    f, p = dsp.welch(x, fs=25000.0, nperseg=nperseg, noverlap=noverlap, nfft=nfft)
    fr, pr = sig.welch(x, fs=25000.0, nperseg=nperseg, noverlap=noverlap, nfft=nfft)
    np.testing.assert_allclose(f, fr, rtol=1e-12)
    np.testing.assert_allclose(p, pr, rtol=1e-9, atol=1e-12 * pr.max())
    # The sine's line is where it should be.
    assert abs(f[np.argmax(p)] - 1633.0) <= 25000.0 / (nfft or nperseg)


def test_csd_coherence_and_h1_estimate():
    rng = np.random.default_rng(11)
    x = rng.standard_normal(40000)
    sos = sig.butter(2, 500.0, fs=10000.0, output="sos")
    y = sig.sosfilt(sos, x) + 0.01 * rng.standard_normal(x.size)
    f, pxy = dsp.csd(x, y, fs=10000.0, nperseg=512)
    fr, pxyr = sig.csd(x, y, fs=10000.0, nperseg=512)
    np.testing.assert_allclose(pxy, pxyr, rtol=1e-9, atol=1e-12 * np.abs(pxyr).max())
    f, c = dsp.coherence(x, y, fs=10000.0, nperseg=512)
    np.testing.assert_allclose(c, sig.coherence(x, y, fs=10000.0, nperseg=512)[1], rtol=1e-9, atol=1e-12)
    # H1 of a known filter (thesis §3.4's estimator) recovers its response where coherence is high.
    f, h, coh = dsp.tfestimate(x, y, fs=10000.0, nperseg=512)
    _, href = sig.sosfreqz(sos, worN=f, fs=10000.0)
    band = (f > 20.0) & (f < 1000.0)
    assert np.all(coh[band] > 0.99)
    np.testing.assert_allclose(h[band], href[band], rtol=0.05)


def test_mls_equals_scipy():
    for nbits in (4, 8, 13):
        np.testing.assert_array_equal(dsp.max_len_seq(nbits), sig.max_len_seq(nbits)[0])
    np.testing.assert_array_equal(dsp.max_len_seq(8, length=1000), sig.max_len_seq(8, length=1000)[0])
    p = dsp.prbs(7, 127 * 4, clock_divider=4, amplitude=2.0)
    assert set(np.unique(p)) == {-2.0, 2.0}
    np.testing.assert_array_equal(p[::4], 4.0 * sig.max_len_seq(7)[0] - 2.0)


def test_tffit_recovers_a_known_system():
    # Second-order plant of eq. 3.6's form: 1 / (s^2 + 2 zeta w s + w^2) with w = 2 pi 80 Hz.
    w0, zeta = 2 * np.pi * 80.0, 0.05
    num, den = [w0**2], [1.0, 2 * zeta * w0, w0**2]
    f = np.geomspace(5.0, 2000.0, 300)
    _, h = sig.freqs(num, den, worN=2 * np.pi * f)
    r = dsp.tffit(f, h, nz=0, np=2)
    np.testing.assert_allclose(r["den"], den, rtol=1e-6)
    np.testing.assert_allclose(r["num"], num, rtol=1e-6)
    assert r["relative_rms_error"] < 1e-8 and r["dt"] == 0.0
    assert np.all(np.real(r["poles"]) < 0)


def test_bad_inputs_raise_value_error():
    with pytest.raises(ValueError, match="sos: expected an array of shape"):
        dsp.sosfilt(np.zeros((2, 5)), np.zeros(10))
    with pytest.raises(ValueError, match=r"x: non-finite value nan at flat index 3"):
        dsp.sosfilt(sig.butter(2, 0.2, output="sos"), np.array([0.0, 1.0, 2.0, np.nan]))
    with pytest.raises(ValueError, match="x: expected a 1-D array"):
        dsp.welch(np.zeros((3, 300)))
    with pytest.raises(ValueError, match="invalid parameter"):
        dsp.butter(4, 6000.0, fs=10000.0)  # above Nyquist
    with pytest.raises(ValueError, match="invalid parameter"):
        dsp.butter(0, 100.0, fs=10000.0)
    with pytest.raises(ValueError, match="window"):
        dsp.welch(np.zeros(300), window="hamming")
    with pytest.raises(ValueError, match="h: expected a 1-D array of the same length"):
        dsp.tffit(np.arange(1.0, 10.0), np.ones(5, complex))


def test_an_overflowing_spectrum_raises_instead_of_reading_zero():
    # Finite data near 1e308 overflow the squared spectrum; H1 read 0 there.
    import microcobot

    n = np.arange(512)
    x, y = np.sin(0.3 * n), 1e308 * np.sin(0.3 * n + 1.0)
    with pytest.raises(microcobot.ComputationFailed, match="y: the power spectrum overflows"):
        dsp.tfestimate(x, y, fs=1e3)
    with pytest.raises(microcobot.ComputationFailed, match="overflows"):
        dsp.welch(y, fs=1e3)
