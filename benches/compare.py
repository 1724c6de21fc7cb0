"""Speed of ``lugre`` against the plain-loop limit, NumPy and SciPy, in one process.

Every line is a ratio measured in this run (best of a few repeats, wall clock), on the
same closed-loop problem: the paper's axis (``Model.paper()``: 25 kg, LuGre friction,
PID at 10 kHz held between updates, one plant step per control period), tracking a
5 mm sine with 25 periods over the run (stick at each reversal, slip in between),
reference and output on 1001 samples.

- ``lugre.simulate`` (Rust) against ``benches/plain_loop.c`` (the same step as one C
  loop, gcc -O3 for the same baseline x86-64 as the Rust build; -march=native too), the same step as a plain Python loop (floats and
  ``math.exp``; and with NumPy scalars), ``lugre.reference.simulate`` (the NumPy twin),
  and ``scipy.integrate.solve_ivp`` (LSODA, Radau) driving the same closed loop: one
  call per control period with the command held, at a tolerance (rtol 1e-4) that
  reproduces the converged trajectory (lugre with 256 substeps) at least as well as
  lugre's own exact/semi-implicit step does; both errors are printed.
- ``lugre.simulate_batch`` on one core (process pinned with ``sched_setaffinity``) and
  on two.
- the robust linear fit of the inverse dynamics (``irls_linear``, ``irls_linear_grid``:
  IGG-weighted IRLS, 8 rounds) in the core against its NumPy twin and against the NumPy
  code it replaced, on 20 000 rows with 10 % gross errors (``--only linear``);
- ``lugre.fit_static`` against ``scipy.optimize.least_squares`` (soft-L1 loss) on the
  same points; ``lugre.fit_dynamic`` against the eq. 18 least-squares objective over
  ``lugre.reference.simulate`` driven by SciPy's Nelder-Mead.

Run from the repository root after building the extension in release mode::

    python benches/compare.py            # about two minutes
    python benches/compare.py --quick    # smaller sizes, fewer repeats

No assertion is made on times; the numbers go to ``docs/BENCHMARKS.md``.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import lugre
import numpy as np
from lugre import reference

HERE = Path(__file__).resolve().parent
RATE = 1e4
MODEL = lugre.Model.paper()


def machine() -> str:
    cpu = platform.processor() or "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (f"{cpu}, nproc {os.cpu_count()}, load {load:.2f}, Python "
            f"{platform.python_version()}, NumPy {np.__version__}")


def best(fn: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """Shortest wall time of ``repeat`` calls, and the last result."""
    tmin, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        tmin = min(tmin, time.perf_counter() - t0)
    return tmin, out


def grid(steps: int, m: int = 1001) -> tuple[np.ndarray, np.ndarray]:
    """``m`` samples over ``steps`` control periods of a 5 mm sine with 25 periods."""
    t = np.linspace(0.0, steps / RATE, m)
    return t, 5e-3 * np.sin(2 * np.pi * 25.0 * t / t[-1])


def row(name: str, rate: float, base: float | None = None, note: str = "") -> None:
    ratio = f"{base / rate:10.1f}x" if base else " " * 11
    print(f"  {name:<44} {rate / 1e6:9.3f} M steps/s {ratio}  {note}")


# --------------------------------------------------------------------------------------
# the step as plain loops (the same algorithm as benches/plain_loop.c)
# --------------------------------------------------------------------------------------

def plain_loop(t: np.ndarray, xr_in: np.ndarray, steps: int, numpy_scalars: bool) -> float:
    """The closed-loop step as a Python loop; returns the final position."""
    f = np.float64 if numpy_scalars else float
    exp = np.exp if numpy_scalars else math.exp
    fr = MODEL.to_dict()["friction"]
    pos, neg = fr["positive"], fr["negative"]
    sets = {True: tuple(f(pos[k]) for k in ("fc", "fs", "sigma2", "vs")),
            False: tuple(f(neg[k]) for k in ("fc", "fs", "sigma2", "vs"))}
    s0, s1 = f(fr["sigma0"]), f(fr["sigma1"])
    mass, kf, kp, ki, kd, rate = f(25.0), f(25.0), f(5e4), f(5e5), f(1500.0), f(RATE)
    tl, xl = [f(a) for a in t], [f(a) for a in xr_in]
    m = len(tl)
    dec = steps // (m - 1)
    h = f(1.0) / rate
    x, v, z, xi, xr_prev = xl[0], f(0.0), f(0.0), f(0.0), f(0.0)
    out = []
    j = 0
    for n in range(steps + 1):
        tc = n / rate
        while j + 2 < m and tl[j + 1] <= tc:
            j += 1
        if tc >= tl[m - 1]:
            xr = xl[m - 1]
        else:
            xr = xl[j] + (xl[j + 1] - xl[j]) * (tc - tl[j]) / (tl[j + 1] - tl[j])
        xr_dot = f(0.0) if n == 0 else (xr - xr_prev) * rate
        xr_prev = xr
        e = xr - x
        xi += e / rate
        ic = (kp * e + ki * xi + kd * (xr_dot - v)) / kf
        fc, fs, s2, vs = sets[v >= 0.0]
        r = v / vs
        g = fc + (fs - fc) * exp(-(r * r))
        zdot = v - s0 * abs(v) * z / g
        fric = s0 * z + s1 * zdot + s2 * v
        if n % dec == 0:
            out.append((x, v, z, ic, fric, kf * ic))
        if n == steps:
            break
        a = (kf * ic - fric) / mass
        if v != 0.0:
            zss = (1.0 if v > 0.0 else -1.0) * g / s0
            z = zss + (z - zss) * exp(-(s0 * abs(v) * h / g))
        v += a * h
        x += v * h
    return float(x)


def build_c(flags: list[str]) -> Path | None:
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        print("  (no C compiler: plain C loop skipped)")
        return None
    exe = Path(tempfile.gettempdir()) / f"lugre_plain_loop_{os.getpid()}_{len(flags)}"
    subprocess.run([cc, *flags, "-o", str(exe), str(HERE / "plain_loop.c"), "-lm"],
                   check=True)
    return exe


def run_c(exe: Path, t: np.ndarray, xr: np.ndarray, steps: int, repeat: int) -> tuple[float, float]:
    """Best time of the C loop and its final position."""
    with tempfile.NamedTemporaryFile(suffix=".bin", delete=False) as fh:
        fh.write(np.int64(len(t)).tobytes() + t.tobytes() + xr.tobytes())
        path = fh.name
    try:
        tmin, x_end = math.inf, math.nan
        for _ in range(repeat):
            out = subprocess.run([str(exe), path, str(steps)], check=True, capture_output=True,
                                 text=True).stdout
            kv = dict(item.split("=", 1) for item in out.split())
            tmin = min(tmin, float(kv["seconds"]))
            x_end = float(kv["x"])
        return tmin, x_end
    finally:
        os.unlink(path)


# --------------------------------------------------------------------------------------
# solve_ivp on the same closed loop
# --------------------------------------------------------------------------------------

def ivp_closed_loop(t: np.ndarray, xr_in: np.ndarray, periods: int, method: str,
                    rtol: float, atol: Any) -> np.ndarray:
    """PID at 10 kHz, command held, plant (x, v, z) by solve_ivp between control
    instants; returns x at the control instants 0..periods."""
    from scipy.integrate import solve_ivp

    fr = MODEL.to_dict()["friction"]
    sets = {True: tuple(fr["positive"][k] for k in ("fc", "fs", "sigma2", "vs")),
            False: tuple(fr["negative"][k] for k in ("fc", "fs", "sigma2", "vs"))}
    s0, s1, mass = fr["sigma0"], fr["sigma1"], 25.0

    def rhs(_t: float, y: np.ndarray, fm: float) -> list[float]:
        _, v, z = y
        fc, fs, s2, vs = sets[v >= 0.0]
        g = fc + (fs - fc) * math.exp(-((v / vs) ** 2))
        zdot = v - s0 * abs(v) * z / g
        return [v, (fm - (s0 * z + s1 * zdot + s2 * v)) / mass, zdot]

    y = np.array([xr_in[0], 0.0, 0.0])
    xi = xr_prev = 0.0
    xs = np.empty(periods + 1)
    for n in range(periods + 1):
        tc = n / RATE
        xr = float(np.interp(tc, t, xr_in))
        xr_dot = 0.0 if n == 0 else (xr - xr_prev) * RATE
        xr_prev = xr
        e = xr - y[0]
        xi += e / RATE
        fm = 5e4 * e + 5e5 * xi + 1500.0 * (xr_dot - y[1])
        xs[n] = y[0]
        if n == periods:
            break
        sol = solve_ivp(rhs, (tc, (n + 1) / RATE), y, method=method, rtol=rtol, atol=atol,
                        args=(fm,))
        y = sol.y[:, -1]
    return xs


# --------------------------------------------------------------------------------------
# sections
# --------------------------------------------------------------------------------------

def closed_loop(quick: bool) -> None:
    print("\nclosed-loop servo + LuGre step (steps/s; ratio = lugre speed / other speed)")
    steps = 1_000_000 if quick else 10_000_000
    rep = 3 if quick else 7
    t, xr = grid(steps)
    tl, r = best(lambda: lugre.simulate(MODEL, t, xr), rep)
    rate_lugre = steps / tl
    row(f"lugre.simulate ({steps:.0e} steps)", rate_lugre)
    # -O3 alone targets baseline x86-64 like the Rust build (no FMA contraction);
    # -march=native is shown for information. lugre and C alternate, so that both see
    # the same load on a shared machine.
    for flags in (["-O3"], ["-O3", "-march=native"]):
        exe = build_c(flags)
        if exe is None:
            break
        tc = tl2 = math.inf
        try:
            for _ in range(rep):
                tl2 = min(tl2, best(lambda: lugre.simulate(MODEL, t, xr), 1)[0])
                tcr, x_end = run_c(exe, t, xr, steps, 1)
                tc = min(tc, tcr)
        finally:
            exe.unlink(missing_ok=True)
        row(f"plain C loop (gcc {' '.join(flags)})", steps / tc, steps / tl2,
            f"lugre at {tc / tl2:.0%} of C ({steps / tl2 / 1e6:.2f} M steps/s in these "
            f"rounds); |x_end diff| {abs(x_end - r.x[-1]):.1e} m")

    n_py = 20_000 if quick else 100_000
    tp, xr_p = grid(n_py)
    tpy, x_py = best(lambda: plain_loop(tp, xr_p, n_py, False), 2)
    r_small = lugre.simulate(MODEL, tp, xr_p)
    row("plain Python loop (floats, math.exp)", n_py / tpy, rate_lugre,
        f"|x_end diff| {abs(x_py - r_small.x[-1]):.1e} m")
    n_np = n_py // 5
    tn, xr_n = grid(n_np)
    tnp, _ = best(lambda: plain_loop(tn, xr_n, n_np, True), 2)
    row("plain Python loop (NumPy scalars)", n_np / tnp, rate_lugre)
    n_ref = n_py // 5
    tr, xr_r = grid(n_ref)
    tref, rr = best(lambda: reference.simulate(MODEL, tr, xr_r), 2)
    rl = lugre.simulate(MODEL, tr, xr_r)
    row("lugre.reference.simulate (NumPy twin)", n_ref / tref, rate_lugre,
        f"max |x diff| {np.max(np.abs(rr.x - rl.x)):.1e} m")

    # solve_ivp: x at every control instant against the converged trajectory
    periods = 500 if quick else 2500
    ti = np.arange(periods + 1) / RATE
    t_i, xr_i = ti, 5e-3 * np.sin(2 * np.pi * 2.0 * ti)
    conv = lugre.simulate(MODEL, t_i, xr_i, substeps=256).x
    own = lugre.simulate(MODEL, t_i, xr_i).x
    err_own = np.max(np.abs(own - conv))
    print(f"  (solve_ivp: {periods} control periods; lugre's own step error against "
          f"substeps=256: {err_own:.1e} m)")
    for method in ("LSODA", "Radau"):
        # rtol 1e-4 already reproduces the converged trajectory better than lugre's
        # own step does (tighter costs LSODA more time; Radau hardly changes)
        tiv, xs = best(lambda m=method: ivp_closed_loop(t_i, xr_i, periods, m, 1e-4,
                                                        [1e-7, 1e-5, 1e-9]), 1)
        err = np.max(np.abs(xs - conv))
        row(f"solve_ivp {method} (rtol 1e-4)", periods / tiv, rate_lugre,
            f"error {err:.1e} m")


def batch(quick: bool) -> None:
    print("\nsimulate_batch: 8 models x 2e5 steps, one process pinned to 1 core, then 2")
    if not hasattr(os, "sched_setaffinity") or (os.cpu_count() or 1) < 2:
        print("  (needs Linux and two cores: skipped)")
        return
    steps = 50_000 if quick else 200_000
    t, xr = grid(steps)
    models = []
    for k in range(8):
        d = MODEL.to_dict()
        d["friction"]["sigma0"] = 5e4 + 1e4 * k
        models.append(lugre.Model.from_dict(d))
    cpus = sorted(os.sched_getaffinity(0))
    total = steps * len(models)

    def pin(sel: list[int]) -> None:
        # every thread of the process, the worker pool included
        for tid in os.listdir("/proc/self/task"):
            try:
                os.sched_setaffinity(int(tid), sel)
            except OSError:
                pass

    lugre.simulate_batch(models[:2], t[:11], xr[:11])  # start the worker pool
    try:
        pin(cpus[:1])
        t1, _ = best(lambda: lugre.simulate_batch(models, t, xr), 3)
        pin(cpus[:2])
        t2, _ = best(lambda: lugre.simulate_batch(models, t, xr), 3)
    finally:
        pin(cpus)
    print(f"  1 core  {total / t1 / 1e6:8.2f} M steps/s")
    print(f"  2 cores {total / t2 / 1e6:8.2f} M steps/s   speed-up {t1 / t2:.2f}")


def static_points(n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(1)
    s = 2e-4 * 2000.0 ** (np.arange(n) / (n - 1))
    v = np.concatenate([s, -s])
    f = lugre.stribeck(v, MODEL) * (1 + 0.01 * rng.standard_normal(2 * n))
    f[::10] *= 1.3  # one outlier in ten
    return v, f


def scipy_static_fit(v: np.ndarray, f: np.ndarray) -> list[np.ndarray]:
    """Stribeck parameters (fc, fs, sigma2, vs) per direction by least_squares with
    the robust soft-L1 loss."""
    from scipy.optimize import least_squares

    def res(p: np.ndarray, a: np.ndarray, y: np.ndarray) -> np.ndarray:
        fc, fs, s2, vs = p
        return fc + (fs - fc) * np.exp(-((a / vs) ** 2)) + s2 * a - y

    return [least_squares(res, [20.0, 50.0, 100.0, 0.02], loss="soft_l1", f_scale=1.0,
                          bounds=(1e-9, np.inf), args=(np.abs(v[sel]), np.abs(f[sel]))).x
            for sel in (v > 0, v < 0)]


def static_fit(quick: bool) -> None:
    print("\nstatic (Stribeck) fit, both directions (time per fit)")
    for n in (20, 100) if quick else (20, 100, 1000, 10000):
        v, f = static_points(n)
        tl, fit = best(lambda v=v, f=f: lugre.fit_static(v, f), 5)
        ts, ps = best(lambda v=v, f=f: scipy_static_fit(v, f), 5)
        print(f"  {2 * n:5d} points: lugre {tl * 1e3:8.3f} ms (IGG IRLS, fs+ "
              f"{fit.positive.params['fs']:.2f}); least_squares soft_l1 {ts * 1e3:8.3f} ms "
              f"(fs+ {ps[0][1]:.2f}); ratio {ts / tl:.1f}x")


def dynamic_fit(quick: bool) -> None:
    from scipy.optimize import minimize

    print("\ndynamic (sigma0, sigma1) fit on a closed-loop record")
    dur = 0.5 if quick else 1.0
    t = np.arange(int(dur * RATE) + 1) / RATE
    xr = np.where(t < dur / 2, 1e-3 * t, 1e-3 * (dur - t))
    sim = lugre.simulate(MODEL, t, xr)
    xq = np.round(sim.x / 1e-6) * 1e-6
    rec = lugre.Recording(t=t, x=xq, x_ref=xr, i=sim.i)
    d = MODEL.to_dict()
    d["friction"]["sigma0"], d["friction"]["sigma1"] = 3e4, 100.0
    start = lugre.Model.from_dict(d)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tl, fit = best(lambda: lugre.fit_dynamic(rec, start), 1)
    n_l = fit.evaluations

    evals = [0]

    def objective(p: np.ndarray) -> float:
        evals[0] += 1
        dd = MODEL.to_dict()
        dd["friction"]["sigma0"], dd["friction"]["sigma1"] = math.exp(p[0]), math.exp(p[1])
        x = reference.simulate(lugre.Model.from_dict(dd), t, xr).x
        return float(np.sum((xq - x) ** 2))

    t0 = time.perf_counter()
    res = minimize(objective, np.log([3e4, 100.0]), method="Nelder-Mead",
                   options={"xatol": 1e-3, "fatol": 1e-16, "maxfev": 60 if quick else 200})
    ts = time.perf_counter() - t0
    s0 = math.exp(res.x[0])
    print(f"  lugre.fit_dynamic: {tl:7.2f} s, {n_l} simulations, sigma0 {fit.sigma0:.4g}")
    print(f"  Nelder-Mead over lugre.reference.simulate: {ts:7.2f} s, {evals[0]} simulations, "
          f"sigma0 {s0:.4g}")
    per_l = tl / n_l
    print(f"  time per simulation: lugre {per_l * 1e3:.2f} ms, reference "
          f"{ts / evals[0] * 1e3:.1f} ms (ratio {ts / evals[0] / per_l:.0f}x); "
          f"whole fit ratio {ts / tl:.1f}x")


def linear_problem(n: int, seed: int = 0) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:
    """``n`` rows shaped like the inverse-dynamics fit: 5 base columns (acceleration,
    per-direction Coulomb and viscous terms), 15 candidate pairs of Stribeck humps,
    0.3 N noise and 10 % gross errors of 3 to 30 N."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 20.0, n)
    v = 0.2 * np.sin(2 * np.pi * 0.5 * t) + 0.01 * rng.standard_normal(n)
    a = np.gradient(v, t)
    pos, neg = (v > 0).astype(float), (v < 0).astype(float)
    X = np.column_stack([a, pos, pos * v, -neg, neg * v])
    extras = [np.column_stack([pos * np.exp(-(v / vs) ** 2), -neg * np.exp(-(v / vs) ** 2)])
              for vs in 0.2 * np.logspace(-2.5, -0.5, 15)]
    y = X @ [25.0, 20.0, 300.0, 21.0, 310.0] + extras[9] @ [30.0, 35.0]
    y += 0.3 * rng.standard_normal(n)
    bad = rng.random(n) < 0.1
    y[bad] += rng.uniform(3.0, 30.0, bad.sum()) * rng.choice([-1.0, 1.0], bad.sum())
    return X, extras, y


def former_numpy_irls(X: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, float]:
    """The NumPy IRLS ``diagnosis/inverse.py`` held before the core took it over."""
    w = np.ones(X.shape[0])
    b = np.zeros(X.shape[1])
    for _ in range(8):
        G = np.einsum("ij,ik,i->jk", X, X, w)
        b = np.linalg.solve(G + 1e-12 * np.trace(G) * np.eye(G.shape[0]),
                            np.einsum("ij,i->j", X, w * y))
        e = y - np.einsum("ij,j->i", X, b)
        s = 1.4826 * np.median(np.abs(e - np.median(e))) + 1e-12
        u = np.abs(e) / s
        w = np.where(u <= 1.5, 1.0, np.where(u <= 2.5, 1.5 / u, 0.0))
    e = y - np.einsum("ij,j->i", X, b)
    return b, float(np.sum(w * e * e))


def linear_fit(quick: bool) -> None:
    from lugre import _core, _native

    n = 2000 if quick else 20000
    X, extras, y = linear_problem(n)
    X7 = np.column_stack([X, extras[7]])
    rep = 3 if quick else 10
    print(f"\nrobust linear fit (IGG IRLS, 8 rounds), {n} rows, core on "
          f"{_core.num_threads()} threads for the grid")
    tc, fc = best(lambda: _native.irls_linear(X7, y), rep)
    tr, fr = best(lambda: reference.irls_linear(X7, y), rep)
    to, (bo, _) = best(lambda: former_numpy_irls(X7, y), rep)
    same = np.array_equal(fc.coef, fr.coef) and np.array_equal(fc.weights, fr.weights)
    dev = float(np.max(np.abs(fc.coef - bo) / np.abs(bo)))
    print(f"  irls_linear, 7 columns: core {tc * 1e3:7.2f} ms, NumPy twin {tr * 1e3:7.2f} ms "
          f"({tr / tc:.1f}x), former NumPy code {to * 1e3:7.2f} ms ({to / tc:.1f}x); "
          f"core == twin bit for bit: {same}; largest relative difference to the former "
          f"code {dev:.1e}")
    tc, gc = best(lambda: _native.irls_linear_grid(X, extras, y), max(rep // 2, 1))
    tr, gr = best(lambda: reference.irls_linear_grid(X, extras, y), max(rep // 5, 1))

    def former_grid() -> int | None:
        best_sse, chosen = former_numpy_irls(X, y)[1], None
        for k, c in enumerate(extras):
            b, sse = former_numpy_irls(np.column_stack([X, c]), y)
            if b[-1] > 0 and b[-2] > 0 and sse < 0.98 * best_sse:
                best_sse, chosen = sse, k
        return chosen

    to, co = best(former_grid, max(rep // 5, 1))
    same = gc.chosen == gr.chosen and np.array_equal(gc.fit.coef, gr.fit.coef)
    print(f"  irls_linear_grid, 5 + 15 x 2 columns: core {tc * 1e3:7.2f} ms, NumPy twin "
          f"{tr * 1e3:7.2f} ms ({tr / tc:.1f}x), former NumPy code {to * 1e3:7.2f} ms "
          f"({to / tc:.1f}x); chosen {gc.chosen} / {gr.chosen} / {co}; core == twin bit for "
          f"bit: {same}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller sizes, fewer repeats")
    ap.add_argument("--only", choices=["closed_loop", "batch", "linear", "static", "dynamic"],
                    action="append", help="run only these sections")
    a = ap.parse_args()
    print(f"lugre {lugre.__version__} | {machine()}")
    sections = {"closed_loop": closed_loop, "batch": batch, "linear": linear_fit,
                "static": static_fit, "dynamic": dynamic_fit}
    for name, fn in sections.items():
        if not a.only or name in a.only:
            fn(a.quick)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
