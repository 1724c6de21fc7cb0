"""The plant of the servo simulation (``Physics`` in ``src/servo/sim.rs``): the state, the
two bodies of a resonance, the effects' forces, the current loop and the two
integrators."""

from __future__ import annotations

import math
from bisect import bisect_right

from ..vocabulary import (
    COGGING,
    CURRENT_LAG,
    CURRENT_LIMIT,
    DEADBAND,
    DELAY,
    DRAG,
    DRIFT,
    FORCE_RIPPLE,
    GRAVITY,
    LOAD_FRICTION,
    OFFSET,
    POSITION_FRICTION,
    RESONANCE,
    SPRING,
    STRIBECK_SHAPE,
)
from .checks import _ceil_f
from .friction import _advance_z, _eval, _eval_loaded, _eval_shaped
from .parsed import _CurrentLoop, _Parsed

__all__: list[str] = []

_PI = math.pi
_exp = math.exp


def _interp_clamped(xp: tuple[float, ...], fp: tuple[float, ...], x: float) -> float:
    n = len(xp)
    if x <= xp[0]:
        return fp[0]
    if x >= xp[n - 1]:
        return fp[n - 1]
    j = bisect_right(xp, x)  # first index with xp[j] > x
    x0, x1 = xp[j - 1], xp[j]
    return fp[j - 1] + (fp[j] - fp[j - 1]) * (x - x0) / (x1 - x0)


class _State:
    __slots__ = ("fl", "ia", "q", "v", "vl", "x", "xl", "z")

    def __init__(self, x: float, v: float, z: float) -> None:
        self.x, self.v, self.z = x, v, z
        self.ia = self.q = self.fl = 0.0
        self.xl, self.vl = x, v  # load (resonance)


class _TwoMass:
    """The two bodies of the ``resonance`` effect (``TwoMass`` in sim.rs)."""

    def __init__(self, mass: float, frequency_hz: float, damping_ratio: float,
                 r: float) -> None:
        self.mm = (1.0 - r) * mass
        self.ml = r * mass
        w = 2.0 * _PI * frequency_hz
        self.k = self.ml * (w * w)
        self.c = 2.0 * damping_ratio * math.sqrt(self.k * self.ml)

    def free_mode(self) -> tuple[float, float]:
        """Angular frequency and damping ratio of the relative motor-load motion."""
        mu = self.mm * self.ml / (self.mm + self.ml)
        w = math.sqrt(self.k / mu)
        return w, self.c / (2.0 * mu * w)


class _Physics:
    """Extra physics flattened for the inner loop (``Physics`` in sim.rs)."""

    def __init__(self, m: _Parsed, t0: float) -> None:
        self.mass = m.total_mass
        self.kf = m.axis.force_constant
        self.fr = m.friction
        self.lin_a = 0.0
        self.lin_b = 0.0
        self.cogging: list[tuple[float, float, float]] = []
        self.pos_scale: list[tuple[tuple[float, ...], tuple[float, ...]]] = []
        self.drift: list[tuple[float, float]] = []
        self.current_loop: _CurrentLoop | None = m.axis.current_loop
        self.lag_w: float | None = None
        self.delay: float | None = None
        self.t0 = t0
        self.shape: float | None = None
        self.drag = 0.0
        self.deadband: float | None = None
        self.limit: float | None = None
        self.ripple: list[tuple[float, float, float]] = []
        self.load_coef: float | None = None  # load_friction
        self.res: _TwoMass | None = None
        for e in m.effects:
            q = e.params
            if e.kind == COGGING:
                w = 2.0 * _PI / q["pitch"]
                self.cogging.append((q["amplitude"], w, q["phase"]))
                for k, (a, ph) in enumerate(q["harmonics"]):
                    self.cogging.append((a, w * (k + 2.0), ph))
            elif e.kind == GRAVITY:  # one term of wavenumber 1: torque*sin(x + phase)
                self.cogging.append((q["torque"], 1.0, q["phase"]))
            elif e.kind == CURRENT_LIMIT:
                self.limit = q["current"]
            elif e.kind == FORCE_RIPPLE:
                self.ripple.append((q["amplitude"], 2.0 * _PI / q["pitch"], q["phase"]))
            elif e.kind == LOAD_FRICTION:
                self.load_coef = q["coefficient"]
            elif e.kind == SPRING:
                self.lin_a += q["stiffness"]
                self.lin_b -= q["stiffness"] * q["x0"]
            elif e.kind == OFFSET:
                self.lin_b += q["force"]
            elif e.kind == POSITION_FRICTION:
                self.pos_scale.append((q["positions"], q["scale"]))
            elif e.kind == DRIFT:
                self.drift.append((q["gain"], q["time_constant"]))
            elif e.kind == DELAY:
                self.delay = q["seconds"]
            elif e.kind == CURRENT_LAG:
                self.lag_w = 2.0 * _PI * q["bandwidth_hz"]
            elif e.kind == RESONANCE:
                self.res = _TwoMass(self.mass, q["frequency_hz"], q["damping_ratio"],
                                    q["load_fraction"])
            elif e.kind == DEADBAND:
                self.deadband = q["current"]
            elif e.kind == DRAG:
                self.drag += q["coefficient"]
            elif e.kind == STRIBECK_SHAPE:
                self.shape = q["exponent"]
        self.has_scale = bool(self.pos_scale) or bool(self.drift)

    def scale(self, x: float, time: float) -> float:
        if not self.has_scale:
            return 1.0
        s = 1.0
        for xp, fp in self.pos_scale:
            s *= _interp_clamped(xp, fp, x)
        for gain, tau in self.drift:
            s *= 1.0 - gain * (1.0 - _exp(-(time - self.t0) / tau))
        return s

    def load(self, s: _State) -> tuple[float, float]:
        """Position and velocity of the body carrying friction and effects."""
        return (s.xl, s.vl) if self.res is not None else (s.x, s.v)

    def friction(self, z: float, v: float, scale: float, fm: float
                 ) -> tuple[float, float, float]:
        """``(g, F, zdot)`` of the plant's friction (``stribeck_shape`` applied, the levels
        raised by a ``load_friction`` under the motor force ``fm``)."""
        if self.load_coef is not None:
            return _eval_loaded(self.fr, z, v, scale, self.load_coef * abs(fm), self.shape)
        if self.shape is not None:
            return _eval_shaped(self.fr, z, v, scale, self.shape)
        return _eval(self.fr, z, v, scale)

    def drive_force(self, i: float) -> float:
        """The motor force before a lag: ``K_F*clip(db(i))`` (``deadband``, then
        ``current_limit``; ``Actuator::current`` in effects.rs)."""
        c = self.deadband
        if c is not None:
            i = i - c if i > c else (i + c if i < -c else 0.0)
        lim = self.limit
        if lim is not None:
            i = max(min(i, lim), -lim)  # f64::clamp
        return self.kf * i

    def ripple_of(self, f: float, x: float) -> float:
        """``f`` times the ``force_ripple`` factor ``1 + sum A*sin(w*x + phase)``."""
        if not self.ripple:
            return f
        r = 1.0
        for a, w, ph in self.ripple:
            r += a * math.sin(w * x + ph)
        return f * r

    def effect_force(self, x: float, v: float) -> float:
        f = self.lin_a * x + self.lin_b
        for a, w, ph in self.cogging:
            f += a * math.sin(w * x + ph)
        if self.drag != 0.0:
            f += self.drag * abs(v) * v
        return f

    def accel(
        self, fm: float, x: float, v: float, z: float, time: float
    ) -> tuple[float, float, float]:
        s = self.scale(x, time)
        g, f, zdot = self.friction(z, v, s, fm)
        return (fm - f - self.effect_force(x, v)) / self.mass, g, zdot

    def motor(self, s: _State, ic: float, h: float) -> float:
        """Advance the current (loop) and the lagged force over ``h``; the motor force
        (dead band, current limit, lag, then the ripple at the step's start)."""
        cl = self.current_loop
        if cl is None:
            s.ia = ic
        elif cl.kind == "first_order":
            s.ia = ic + (s.ia - ic) * _exp(-2.0 * _PI * cl.bandwidth_hz * h)
        else:
            r, ind, ke, kp, ki = cl.resistance, cl.inductance, cl.back_emf, cl.kp, cl.ki
            wc = kp / ind
            ns = max(math.ceil(h * wc * 4.0), 1)
            hs = h / ns
            v = s.v

            def d(ia: float, q: float) -> tuple[float, float]:
                return (kp * (ic - ia) + ki * q - r * ia - ke * v) / ind, ic - ia

            for _ in range(ns):
                a1, b1 = d(s.ia, s.q)
                a2, b2 = d(s.ia + 0.5 * hs * a1, s.q + 0.5 * hs * b1)
                a3, b3 = d(s.ia + 0.5 * hs * a2, s.q + 0.5 * hs * b2)
                a4, b4 = d(s.ia + hs * a3, s.q + hs * b3)
                s.ia += hs / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
                s.q += hs / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4)
        fm = self.drive_force(s.ia)
        if self.lag_w is not None:
            s.fl = fm + (s.fl - fm) * _exp(-self.lag_w * h)
            fm = s.fl
        return self.ripple_of(fm, s.x)

    def step_exact(self, s: _State, ic: float, h: float, time: float) -> None:
        fm = self.motor(s, ic, h)
        r = self.res
        if r is not None:
            # two bodies: semi-implicit Euler for both, exact bristle update on the load
            g, f, _ = self.friction(s.z, s.vl, self.scale(s.xl, time), fm)
            fc = r.k * (s.x - s.xl) + r.c * (s.v - s.vl)
            am = (fm - fc) / r.mm
            al = (fc - f - self.effect_force(s.xl, s.vl)) / r.ml
            s.z = _advance_z(self.fr, s.z, s.vl, g, h)
            s.v += am * h
            s.vl += al * h
            s.x += s.v * h
            s.xl += s.vl * h
            return
        a, g, _ = self.accel(fm, s.x, s.v, s.z, time)
        s.z = _advance_z(self.fr, s.z, s.v, g, h)
        s.v += a * h
        s.x += s.v * h

    def step_rk4_two_mass(self, s: _State, fm: float, r: _TwoMass, h: float,
                          time: float) -> None:
        """RK4 on ``(x, v, xl, vl, z)`` of the two-mass axis, the motor force held."""

        def d(x: float, v: float, xl: float, vl: float, z: float,
              tm: float) -> tuple[float, float, float, float, float]:
            _, f, zdot = self.friction(z, vl, self.scale(xl, tm), fm)
            fc = r.k * (x - xl) + r.c * (v - vl)
            return v, (fm - fc) / r.mm, vl, (fc - f - self.effect_force(xl, vl)) / r.ml, zdot

        x, v, xl, vl, z = s.x, s.v, s.xl, s.vl, s.z
        k1 = d(x, v, xl, vl, z, time)
        k2 = d(x + 0.5 * h * k1[0], v + 0.5 * h * k1[1], xl + 0.5 * h * k1[2],
               vl + 0.5 * h * k1[3], z + 0.5 * h * k1[4], time + 0.5 * h)
        k3 = d(x + 0.5 * h * k2[0], v + 0.5 * h * k2[1], xl + 0.5 * h * k2[2],
               vl + 0.5 * h * k2[3], z + 0.5 * h * k2[4], time + 0.5 * h)
        k4 = d(x + h * k3[0], v + h * k3[1], xl + h * k3[2], vl + h * k3[3], z + h * k3[4],
               time + h)
        s.x += h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0])
        s.v += h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1])
        s.xl += h / 6.0 * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2])
        s.vl += h / 6.0 * (k1[3] + 2.0 * k2[3] + 2.0 * k3[3] + k4[3])
        s.z += h / 6.0 * (k1[4] + 2.0 * k2[4] + 2.0 * k3[4] + k4[4])

    def rk4_pieces(self, z: float, v: float, x: float, fm: float, h: float, time: float
                   ) -> int:
        """Pieces of an RK4 step keeping ``sigma0*|v|*h/g`` under the limit
        (``Physics::rk4_pieces``)."""
        if v == 0.0:
            return 1
        g, _, _ = self.friction(z, v, self.scale(x, time), fm)
        q = self.fr.sigma0 * abs(v) * h / g
        if math.isnan(q) or q <= _RK4_BRISTLE_LIMIT:  # (NaN: the divergence check)
            return 1
        return int(min(_ceil_f(q / _RK4_BRISTLE_LIMIT), _RK4_MAX_PIECES))

    def step_rk4(self, s: _State, ic: float, h_step: float, time: float) -> None:
        """One plant step of RK4, the motor force held, in equal pieces where the
        bristles would make it unstable (``Physics::step_rk4``)."""
        fm = self.motor(s, ic, h_step)
        x, v = (s.xl, s.vl) if self.res is not None else (s.x, s.v)
        p = self.rk4_pieces(s.z, v, x, fm, h_step, time)
        h = h_step / float(p)
        for j in range(p):
            tj = time + float(j) * h
            if self.res is not None:
                self.step_rk4_two_mass(s, fm, self.res, h, tj)
            else:
                self.step_rk4_one_mass(s, fm, h, tj)

    def step_rk4_one_mass(self, s: _State, fm: float, h: float, time: float) -> None:
        """RK4 on ``(x, v, z)`` of the rigid axis, the motor force held."""

        def d(x: float, v: float, z: float, tm: float) -> tuple[float, float, float]:
            a, _, zdot = self.accel(fm, x, v, z, tm)
            return v, a, zdot

        x, v, z = s.x, s.v, s.z
        k1 = d(x, v, z, time)
        k2 = d(x + 0.5 * h * k1[0], v + 0.5 * h * k1[1], z + 0.5 * h * k1[2], time + 0.5 * h)
        k3 = d(x + 0.5 * h * k2[0], v + 0.5 * h * k2[1], z + 0.5 * h * k2[2], time + 0.5 * h)
        k4 = d(x + h * k3[0], v + h * k3[1], z + h * k3[2], time + h)
        s.x += h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0])
        s.v += h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1])
        s.z += h / 6.0 * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2])


#: Largest ``sigma0*|v|*h/g`` of one RK4 step (``RK4_BRISTLE_LIMIT`` in sim.rs).
_RK4_BRISTLE_LIMIT = 1.0
#: Most pieces of one RK4 plant step (``RK4_MAX_PIECES``).
_RK4_MAX_PIECES = 1e4
