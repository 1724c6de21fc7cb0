"""The diagnosis's signal processing without SciPy (:mod:`lugre.diagnosis.dsp`) gives
SciPy's numbers bit for bit, and the diagnosis imports no ``scipy.signal`` (issue 28: an
import that cost twice the diagnosis of a 20 000-sample record)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from lugre.diagnosis import dsp
from scipy import signal, stats


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


@pytest.mark.parametrize("q,dof", [(0.3, 10.0), (0.5, 3.6), (0.3, 250.2), (0.5, 1e4)])
def test_chi2_ppf_is_scipys(q, dof):
    assert dsp.chi2_ppf(q, dof) == stats.chi2.ppf(q, dof)


def test_diagnosis_imports_no_scipy_signal():
    code = ("import sys, lugre\n"
            "from lugre.diagnosis import diagnose\n"
            "from lugre.diagnosis.synth import concealed\n"
            "rec, model, _ = concealed('cogging', duration=4.0)\n"
            "diagnose(rec, model, closed_loop=False)\n"
            "heavy = [m for m in ('scipy.signal', 'scipy.stats', 'scipy.interpolate',\n"
            "         'scipy.optimize', 'matplotlib') if m in sys.modules]\n"
            "print(','.join(heavy))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == ""
