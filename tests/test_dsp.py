"""The diagnosis's signal processing and distributions without SciPy
(:mod:`lugre.diagnosis.dsp`) give SciPy's numbers (the filter design and the spectra bit
for bit, the distributions to 1e-13), and a diagnosis imports no SciPy at all (issue 28:
``scipy.signal`` cost twice the diagnosis of a 20 000-sample record, ``scipy.special``
half of it)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from lugre.diagnosis import dsp
from scipy import signal, special, stats


@pytest.mark.parametrize("order", range(1, 9))
def test_butter_sos_is_scipys(order):
    rng = np.random.default_rng(order)
    for wn in [*rng.uniform(0.001, 0.98, 40), 0.08, 0.1, 0.5, 0.2 / 3]:
        np.testing.assert_array_equal(dsp.butter_sos(order, wn),
                                      signal.butter(order, wn, output="sos"))


def test_butter_sos_refuses_a_band_outside_nyquist():
    with pytest.raises(ValueError):
        dsp.butter_sos(4, 1.0)


@pytest.mark.parametrize("n,nper", [(300, 256), (300, 1024), (1000, 1000), (1024, 256),
                                    (5000, 4096), (20001, 1024), (20001, 20001),
                                    (100000, 16384)])
def test_welch_is_scipys(n, nper):
    y = np.cumsum(np.random.default_rng(n).standard_normal(n))
    with pytest.warns(UserWarning) if nper > n else _nothing():
        f1, p1 = signal.welch(y, fs=1000.0, nperseg=nper)
    f2, p2 = dsp.welch(y, 1000.0, nper)
    np.testing.assert_array_equal(f1, f2)
    np.testing.assert_array_equal(p1, p2)


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_sosfreqz_is_scipys():
    sos = signal.butter(4, 0.08, output="sos")
    ff = np.linspace(0.0, 500.0, 4001)
    np.testing.assert_array_equal(dsp.sosfreqz(sos, ff, 1000.0),
                                  signal.sosfreqz(sos, worN=ff, fs=1000.0)[1])


@pytest.mark.parametrize("q", [1e-6, 0.01, 0.3, 0.5, 0.99])
@pytest.mark.parametrize("dof", [1.0, 1.8, 3.6, 10.0, 17.1, 250.2, 1e4, 3.3e5])
def test_chi2_ppf_agrees_with_scipy(q, dof):
    assert dsp.chi2_ppf(q, dof) == pytest.approx(stats.chi2.ppf(q, dof), rel=1e-12)


@pytest.mark.parametrize("k", [1, 2, 3, 9, 10, 19, 29])
def test_t_cdf_agrees_with_scipy_tails_included(k):
    t = np.concatenate([np.linspace(-40.0, 40.0, 161), [-1e3, -100.0, -2.0, -1.999, 1e3]])
    np.testing.assert_allclose(dsp.t_cdf(k, t), special.stdtr(k, t), rtol=1e-13, atol=0)
    assert dsp.t_cdf(k, np.inf) == 1.0 and dsp.t_cdf(k, -np.inf) == 0.0
    assert dsp.t_cdf(k, 0.0) == 0.5


@pytest.mark.parametrize("x", [0.0, 1e-10, 0.1, 1.0, 10.0, 100.0, 700.0, 1400.0])
def test_chi2_sf1_agrees_with_scipy(x):
    assert dsp.chi2_sf1(x) == pytest.approx(special.chdtrc(1, x), rel=1e-13, abs=0)


def test_diagnosis_imports_no_scipy():
    code = ("import sys, lugre\n"
            "from lugre.diagnosis import diagnose\n"
            "from lugre.diagnosis.synth import concealed\n"
            "rec, model, _ = concealed('cogging', duration=4.0)\n"
            "diagnose(rec, model)\n"
            "heavy = [m for m in ('scipy', 'matplotlib') if m in sys.modules]\n"
            "print(','.join(heavy))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == ""
