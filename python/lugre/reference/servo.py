"""The servo simulation (``src/servo/sim.rs``): the digital controller (or the open-loop
command) and the plant advanced between events; :func:`simulate` and
:func:`simulate_batch`."""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from typing import Any, Callable

from .._args import as_array as _array
from .._args import check_substeps_type as _check_substeps_type
from .._args import select_drive as _select_drive
from .._result import SimResult
from ..exceptions import DataError, InputError, ModelError, ParameterError, _fmt_f64
from ..model import ModelLike
from ..vocabulary import RESONANCE
from .checks import _check_finite, _check_len, _check_time, _finite_option, _parsed
from .friction import _Compensator, _stribeck1
from .parsed import _Parsed
from .plant import _Physics, _State, _TwoMass

__all__ = ["simulate", "simulate_batch"]

_PI = math.pi


class _Interp:
    """``np.interp`` with a forward-moving cursor (queries must not decrease)."""

    def __init__(self, t: list[float], y: list[float]) -> None:
        self.t, self.y, self.j, self.n = t, y, 0, len(t)

    def at(self, tq: float) -> float:
        t, y, n = self.t, self.y, self.n
        if tq <= t[0]:
            return y[0]
        if tq >= t[n - 1]:
            return y[n - 1]
        while self.j + 1 < n and t[self.j + 1] <= tq:
            self.j += 1
        j = self.j
        t0, t1 = t[j], t[j + 1]
        if tq == t0:
            return y[j]
        y0 = y[j]
        return y0 + (y[j + 1] - y0) * (tq - t0) / (t1 - t0)


def _ic_eff_peek(queue: deque[tuple[float, float]], current: float, time: float,
                 tol: float) -> float:
    """The delayed command that would act at ``time`` (for reporting the motor force)."""
    v = current
    for te, val in queue:
        if te <= time + tol:
            v = val
        else:
            break
    return v


def simulate(
    model: ModelLike,
    t: Any,
    x_ref: Any = None,
    *,
    v_ref: Any = None,
    current: Any = None,
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> SimResult:
    """Simulate the axis under its controller (or in open loop), sampled at ``t``.

    The digital controller runs at ``controller.rate_hz`` with its output held between
    updates; the plant is advanced in substeps between events (control instants and
    sample times), as fixed in ``docs/DESIGN.md``.

    Parameters
    ----------
    model : Model, dict or path
        The axis model. Closed loop needs its ``controller``.
    t : array_like
        Sample times [s], strictly increasing; the simulation starts at ``t[0]``.
    x_ref : array_like, optional
        Position reference [m] at ``t`` for a ``pid`` controller.
    v_ref : array_like, optional
        Speed reference [m/s] at ``t`` for a ``pi_speed`` controller.
    current : array_like, optional
        Open loop: current command [A] at ``t``, held between samples (the controller
        is not used). Give exactly one of ``x_ref``, ``v_ref`` and ``current``.
    integrator : {"exact", "rk4"}, default "exact"
        ``"exact"``: exact bristle update with the velocity held and semi-implicit Euler
        for x and v; ``"rk4"``: classic RK4 on (x, v, z), a plant step split in
        equal pieces where ``sigma0*|v|*h/g`` would exceed 1 at its start (beyond 2.78
        the bristles make RK4 unstable).
    substeps : int, default 1
        Plant steps per control period (per sample interval in open loop).
    z0 : float, default 0.0
        Initial bristle deflection [m].
    x0 : float, optional
        Initial position [m]; by default ``x_ref[0]`` (0 without a position reference).
    v0 : float, default 0.0
        Initial velocity [m/s].

    Returns
    -------
    SimResult
        ``t``, ``x``, ``v``, ``z``, ``i``, ``friction`` and ``force`` at the sample times.

    Raises
    ------
    InputError
        ``t`` empty, not finite or not strictly increasing; the drive of another length
        or not finite; the wrong drive for the controller; unknown integrator.
    ParameterError
        ``substeps`` below 1; ``z0``, ``x0`` or ``v0`` not finite.
    ModelError
        Closed loop without a controller.
    DataError
        The simulation diverged.
    """
    return _simulate(_parsed(model), t, x_ref, v_ref=v_ref, current=current,
                     integrator=integrator, substeps=substeps, z0=z0, x0=x0, v0=v0)


def _simulate(
    m: _Parsed,
    t: Any,
    x_ref: Any = None,
    *,
    v_ref: Any = None,
    current: Any = None,
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> SimResult:
    """:func:`simulate` of a parsed model (the estimators change its numbers directly,
    as the core does, without building and checking a document each time)."""
    if integrator not in ("exact", "rk4"):
        raise InputError.at(
            "integrator", f'unknown integrator "{integrator}": use "exact" or "rk4"'
        )
    _check_substeps_type(substeps)
    kind, drive_in = _select_drive(x_ref, v_ref, current)
    ta = _array("t", t)
    tl = ta.tolist()
    ref = _array(kind, drive_in).tolist()
    open_loop = kind == "current"

    substeps, z_init, v_init, x_opt = _check_inputs(m, kind, tl, ref, substeps, z0, v0, x0)
    _check_resonance_step(m, open_loop, tl, substeps)
    return _run(m, ta, tl, kind, ref, integrator, substeps, z_init, v_init, x_opt)


def _check_inputs(m: _Parsed, kind: str, tl: list[float], ref: list[float], substeps: Any,
                  z0: Any, v0: Any, x0: Any) -> tuple[int, float, float, float | None]:
    """The core's ``check_inputs``, in its order: the substeps and the initial state."""
    open_loop = kind == "current"
    _check_time("t", tl)
    name = {"x_ref": "x_ref", "v_ref": "v_ref", "current": "i"}[kind]
    _check_len(name, ref, len(tl), "t")
    _check_finite(name, ref)
    if int(substeps) < 1:
        raise ParameterError.invalid("substeps", float(substeps), "must be at least 1")
    substeps = int(substeps)
    z_init = _finite_option("z0", z0)
    v_init = _finite_option("v0", v0)
    x_opt = None if x0 is None else _finite_option("x0", x0)
    if open_loop:
        if len(tl) < 2:
            raise InputError.at("t", "open-loop simulation needs at least two samples")
    else:
        c = m.controller
        if c is None:
            raise ModelError.at(
                "controller",
                "is missing: closed-loop simulation needs a controller (add one, or "
                "drive the axis with a current)",
            )
        if c.law == "pid" and kind == "v_ref":
            raise InputError.at(
                "v_ref", "the model's controller is a position PID: give x_ref instead"
            )
        if c.law == "pi_speed" and kind == "x_ref":
            raise InputError.at(
                "x_ref", "the model's controller is a PI speed loop: give v_ref instead"
            )
    return substeps, z_init, v_init, x_opt


def _check_resonance_step(m: _Parsed, open_loop: bool, tl: list[float], substeps: int
                          ) -> None:
    """The core's ``check_resonance_step``: plant steps short enough for the free
    motor-load mode of a resonance."""
    for e in m.effects:
        if e.kind == RESONANCE:
            q = e.params
            tm = _TwoMass(m.total_mass, q["frequency_hz"], q["damping_ratio"],
                          q["load_fraction"])
            w, zeta = tm.free_mode()
            limit = math.sqrt(1.0 + zeta * zeta) - zeta
            if not open_loop:
                assert m.controller is not None
                hh = 1.0 / (m.controller.rate_hz * substeps)
            else:
                hh = (tl[-1] - tl[0]) / (len(tl) - 1) / substeps
            if w * hh > limit:
                need = math.ceil(substeps * w * hh / limit)
                raise ParameterError.invalid(
                    "substeps", float(substeps),
                    "is too few for the resonance effect: its free motor-load mode at "
                    f"{w / (2.0 * _PI):.1f} Hz needs plant steps below "
                    f"{limit / (2.0 * _PI):.3f} of its period; use substeps >= {need} "
                    "(or a higher control rate)",
                )


def _run(m: _Parsed, ta: Any, tl: list[float], kind: str, ref: list[float], integrator: str,
         substeps: int, z_init: float, v_init: float, x_opt: float | None) -> SimResult:
    """The simulation of checked inputs (``simulate`` in sim.rs): ``ta`` the sample times
    (``tl`` as floats), ``ref`` the drive."""
    open_loop = kind == "current"
    n_out = len(tl)
    t0 = tl[0]
    phys = _Physics(m, t0)
    ctrl = None if open_loop else m.controller
    rate = ctrl.rate_hz if ctrl is not None else 0.0
    if open_loop:
        h_max = (tl[n_out - 1] - t0) / (n_out - 1) / substeps
        tol = 1e-9 * (tl[n_out - 1] - t0) / (n_out - 1)
    else:
        h_max = 1.0 / (rate * substeps)
        tol = 1e-9 / rate
    interp = _Interp(tl, ref)
    x_init = x_opt if x_opt is not None else (ref[0] if kind == "x_ref" else 0.0)
    s = _State(x_init, v_init, z_init)
    comp = (
        _Compensator(ctrl.ff_friction)
        if ctrl is not None and ctrl.ff_kind == "lugre" and ctrl.ff_friction is not None
        else None
    )
    step: Callable[[_State, float, float, float], None] = (
        phys.step_exact if integrator == "exact" else phys.step_rk4
    )
    lim = m.axis.current_limit
    out_x: list[float] = []
    out_v: list[float] = []
    out_z: list[float] = []
    out_i: list[float] = []
    out_f: list[float] = []
    out_fm: list[float] = []
    queue: deque[tuple[float, float]] = deque()
    xi = 0.0
    xr_prev = 0.0
    ic = 0.0  # latest command
    ic_eff = 0.0  # command acting on the drive (after delay)
    time = t0
    k = 0
    n = 0

    def ctrl_time(n: int) -> float:
        if open_loop:
            return tl[n] if n < n_out else math.inf
        return t0 + n / rate

    tc = ctrl_time(0)
    while True:
        if time >= tc - tol:
            # controller (or open-loop command) update
            if ctrl is not None:
                xr = interp.at(tc)
                if ctrl.law == "pid":
                    xr_dot = 0.0 if n == 0 else (xr - xr_prev) * rate
                    xr_prev = xr
                    e = xr - s.x
                    xi += e / rate
                    u = ctrl.kp * e + ctrl.ki * xi + ctrl.kd * (xr_dot - s.v)
                    vr = xr_dot
                else:
                    e = xr - s.v
                    xi += e / rate
                    u = ctrl.kp * e + ctrl.ki * xi
                    vr = xr
                if ctrl.ff_kind is None or ctrl.ff_friction is None:
                    f_ff = 0.0
                elif ctrl.ff_kind == "static":
                    f_ff = _stribeck1(ctrl.ff_friction, vr)
                else:
                    assert comp is not None
                    f_ff = comp.step(vr, 1.0 / rate)
                ic = (u + f_ff) / phys.kf
                if lim is not None:
                    ic = max(min(ic, lim), -lim)  # f64::clamp
            else:
                ic = ref[n]
            if phys.delay is None:
                ic_eff = ic
            else:
                queue.append((tc + phys.delay, ic))
            n += 1
            tc = ctrl_time(n)
        while k < n_out and tl[k] <= time + tol:
            if phys.current_loop is not None:
                fm = phys.drive_force(s.ia)
            elif phys.delay is not None:
                fm = phys.drive_force(_ic_eff_peek(queue, ic_eff, time, tol))
            else:
                fm = phys.drive_force(ic_eff)
            fm = phys.ripple_of(s.fl if phys.lag_w is not None else fm, s.x)
            xl, vl = phys.load(s)
            sc = phys.scale(xl, time)
            _, f, _ = phys.friction(s.z, vl, sc, fm)
            out_x.append(s.x)
            out_v.append(s.v)
            out_z.append(s.z)
            out_i.append(s.ia if phys.current_loop is not None else ic)
            out_f.append(f)
            out_fm.append(fm)
            k += 1
        if k == n_out:
            break
        nxt = min(tc, tl[k])
        msteps = max(math.ceil((nxt - time) / h_max - 1e-6), 1)
        h = (nxt - time) / msteps
        for j in range(msteps):
            tj = time + j * h
            if phys.delay is not None:
                while queue and queue[0][0] <= tj + tol:
                    ic_eff = queue.popleft()[1]
            step(s, ic_eff, h, tj)
        if not (math.isfinite(s.x) and math.isfinite(s.v) and math.isfinite(s.z)
                and math.isfinite(s.xl) and math.isfinite(s.vl)):
            hint = ("check the current against the mass, or give more substeps" if open_loop
                    else "check the controller gains against the mass and the control rate, "
                    "or give more substeps")
            raise DataError(
                f"data: the simulation diverged at t = {_fmt_f64(time)}: {hint}"
            )
        time = nxt
    return SimResult(ta.copy(), out_x, out_v, out_z, out_i, out_f, out_fm)


def simulate_batch(
    models: Sequence[ModelLike],
    t: Any,
    x_ref: Any = None,
    *,
    v_ref: Any = None,
    current: Any = None,
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> list[SimResult]:
    """Simulate many models on the same input: :func:`simulate` for each, in order.

    Parameters are those of :func:`simulate`, with a sequence of models. As in the core,
    the inputs are converted and every model is checked before the first simulation,
    and the first model that fails raises.

    Returns
    -------
    list of SimResult
        One per model, in order.
    """
    kind, drive = _select_drive(x_ref, v_ref, current)
    _array("t", t)
    _array(kind, drive)
    _check_substeps_type(substeps)
    models = list(models)
    for m in models:
        _parsed(m)
    return [simulate(m, t, integrator=integrator, substeps=substeps, z0=z0, x0=x0, v0=v0,
                     **{kind: drive}) for m in models]
