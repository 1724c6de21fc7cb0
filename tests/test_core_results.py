"""The compiled core returns typed, frozen result classes (``lugre._core.*Result``), not
dicts: each attribute is read-only, no other can be added, arrays are NumPy arrays made
once, and the representation says what the result holds. The facade builds its public
results from these attributes (the twins compare those public results)."""

from __future__ import annotations

import inspect
import warnings

import lugre
import numpy as np
import pytest
from lugre import _core

PAPER = lugre.Model.paper()

#: Attributes of each class, in the order the core fills them.
FIELDS = {
    "SimulationResult": ("x", "v", "z", "i", "friction", "force"),
    "DirectionFitResult": ("fc", "fs", "sigma2", "vs", "std_err", "cov", "ci_low", "ci_high",
                           "indices", "weights", "residuals", "scale", "sigma", "iterations",
                           "converged", "evaluations"),
    "StaticFitResult": ("positive", "negative", "weights", "rejected", "n_zero_speed",
                        "weighting", "notes"),
    "PlateauResult": ("v", "F", "F_std", "n_samples", "plateau", "segment_start",
                      "segment_end", "segment_velocity", "segment_first_used",
                      "segment_settled", "used", "notes"),
    "DynamicFitResult": ("sigma0", "sigma1", "std_err", "ci_low", "ci_high",
                         "rel_ci_half_width", "identifiable", "correlation",
                         "residual_autocorrelation", "notes", "residuals", "weights",
                         "rms_error", "max_error", "objective", "scale", "iterations",
                         "evaluations", "converged"),
    "LinearFitResult": ("coef", "weights", "residuals", "sse", "scale"),
    "GridFitResult": ("chosen", "fit", "base_sse", "sse"),
}


def static_points(gross: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """24 speeds per direction on the paper's curve, one point 30 % off."""
    v = np.concatenate([np.geomspace(2e-4, 0.4, 24), -np.geomspace(2e-4, 0.4, 24)])
    F = lugre.stribeck(v, PAPER)
    if gross:
        F[5] *= 1.3
    return v, F


def plateau_record() -> tuple[np.ndarray, ...]:
    """Four constant-speed plateaus, 0.5 s each at 1 kHz."""
    speeds = np.repeat([0.02, -0.02, 0.05, -0.05], 500)
    t = np.arange(speeds.size) * 1e-3
    x = np.concatenate([[0.0], np.cumsum(speeds[:-1] * 1e-3)])
    return t, x, lugre.stribeck(speeds, PAPER), speeds


def dynamic_record() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A slow ramp under the paper's PID loop, 0.3 s at 10 kHz."""
    t = np.arange(3000) * 1e-4
    x_ref = 2e-3 * t
    return t, x_ref, lugre.simulate(PAPER, t, x_ref).x


def design(rows: int = 60) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(3)
    x = rng.normal(size=(rows, 3))
    y = x @ np.array([1.0, -2.0, 0.5])
    y[7] += 50.0
    return x, y


def core_results() -> dict[str, object]:
    """One result of every class, from the bindings the facade calls."""
    t = np.arange(1000) * 1e-4
    sim = _core.simulate(PAPER._core_model(), t, "x_ref", 0.01 * t)
    batch = _core.simulate_batch([PAPER._core_model()] * 2, t, "x_ref", 0.01 * t)
    assert len(batch) == 2
    v, F = static_points()
    static = _core.fit_static_points(v, F)
    tp, xp, Fp, vr = plateau_record()
    plat = _core.plateaus(tp, xp, Fp, vr)
    td, xr, xm = dynamic_record()
    dyn = _core.fit_dynamic_record(PAPER._core_model(), td, xr, xm, grid=False, max_iter=2)
    x, y = design()
    lin = _core.irls_linear(np.asfortranarray(x), y)
    grid = _core.irls_linear_grid(np.asfortranarray(x[:, :2]), [np.asfortranarray(x[:, 2:])],
                                  y)
    return {"SimulationResult": sim, "SimulationResult (batch)": batch[1],
            "StaticFitResult": static, "DirectionFitResult": static.negative,
            "PlateauResult": plat, "DynamicFitResult": dyn, "LinearFitResult": lin,
            "GridFitResult": grid}


@pytest.fixture(scope="module")
def results() -> dict[str, object]:
    return core_results()


@pytest.mark.parametrize("key", ["SimulationResult", "SimulationResult (batch)",
                                 "StaticFitResult", "DirectionFitResult", "PlateauResult",
                                 "DynamicFitResult", "LinearFitResult", "GridFitResult"])
def test_core_results_are_typed_and_frozen(results, key):
    """Each binding returns its class; its attributes are exactly the listed ones, read
    only, and no attribute can be added; an array attribute is the same object on every
    access (made once, not copied)."""
    name = key.split()[0]
    r = results[key]
    cls = getattr(_core, name)
    assert type(r) is cls
    attrs = tuple(k for k, d in vars(cls).items()
                  if inspect.isdatadescriptor(d) and not k.startswith("_"))
    assert set(attrs) == set(FIELDS[name])
    for k in FIELDS[name]:
        value = getattr(r, k)
        with pytest.raises(AttributeError, match="not writable|readonly"):
            setattr(r, k, value)
        if isinstance(value, np.ndarray):
            assert value.dtype == np.float64 and value.ndim == 1
            assert getattr(r, k) is value
    with pytest.raises(AttributeError):
        r.extra = 1
    with pytest.raises(TypeError):
        cls()


def test_core_results_feed_the_public_results(results):
    """The facade's results carry the core's attributes unchanged."""
    v, F = static_points()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit = lugre.fit_static(v, F)
    core = results["StaticFitResult"]
    for d, c in ((fit.positive, core.positive), (fit.negative, core.negative)):
        assert d.params == {k: getattr(c, k) for k in ("fc", "fs", "sigma2", "vs")}
        np.testing.assert_array_equal(d.cov, np.reshape(c.cov, (4, 4)))
        np.testing.assert_array_equal(d.indices, c.indices)
    assert fit.rejected == core.rejected == [5]
    t = np.arange(1000) * 1e-4
    sim = lugre.simulate(PAPER, t, 0.01 * t)
    for k in FIELDS["SimulationResult"]:
        np.testing.assert_array_equal(getattr(sim, k), getattr(results["SimulationResult"], k))
    x, y = design()
    g = lugre._native.irls_linear_grid(x[:, :2], [x[:, 2:]], y)
    assert g.chosen == results["GridFitResult"].chosen == 0
    np.testing.assert_array_equal(g.fit.coef, results["GridFitResult"].fit.coef)


def test_core_result_reprs_say_what_they_hold(results):
    """The representation names the class and the numbers a reader looks for first."""
    s = repr(results["StaticFitResult"])
    assert s.startswith("StaticFitResult(igg weights, 48 points, 1 rejected, 0 at zero speed")
    assert "positive=DirectionFitResult(fc=28.7, fs=60.2, sigma2=332.5, vs=0.01; 24 points, " \
           "1 rejected" in s
    assert "negative=DirectionFitResult(fc=28.5, fs=60.1, sigma2=333, vs=0.01; 24 points, " \
           "0 rejected" in s
    sim = results["SimulationResult"]
    assert repr(sim) == (f"SimulationResult(1000 samples of x, v, z, i, friction, force; "
                         f"x in [0, {sim.x.max():.6g}] m)")
    dyn = results["DynamicFitResult"]
    assert repr(dyn).startswith(f"DynamicFitResult(sigma0={dyn.sigma0:.6g} (")
    assert f"{dyn.evaluations} evaluations" in repr(dyn)
    plat = results["PlateauResult"]
    assert repr(plat) == ("PlateauResult(4 points from 4 of 4 plateaus settled, "
                          f"{sum(plat.used)} of 2000 samples used, 0 notes)")
    assert repr(results["LinearFitResult"]).startswith(
        "LinearFitResult(coef=[1, -2, 0.5]; 60 rows, 1 rejected, sse ")
    assert repr(results["GridFitResult"]).startswith(
        "GridFitResult(chosen=0 of 1 candidates, base_sse ")
