//! Closed- and open-loop simulation of the servo axis with LuGre friction.
//!
//! The digital controller runs at `rate_hz` and its output is held between updates
//! (zero-order hold); the plant is advanced in substeps between events (control
//! instants and output samples). The default integrator updates the bristle state
//! exactly with the velocity held and the mechanics by semi-implicit Euler: two `exp()`
//! per step, no step-size limit from the bristle stiffness. With a `resonance` effect
//! both bodies (motor and load) advance by semi-implicit Euler, which limits the step
//! against the coupling's mode ([`check_resonance_step`]). RK4 is there for
//! comparison. The algorithm is fixed in `docs/DESIGN.md` and mirrored step for step by
//! `lugre.reference`.

mod checks;
mod plant;

pub use checks::{check_inputs, check_resonance_step};
pub(crate) use plant::TwoMass;

use super::model::{ControlLaw, Controller, FeedforwardKind, Model};
use crate::error::{Error, Result};
use crate::friction::{Compensator, LugreParams};
use plant::{is_plain, Physics, State};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How often a long simulation calls its `keep_going` callback (for Ctrl-C in Python).
///
/// By time, not by steps: from Python the callback has to take the interpreter lock,
/// which a busy Python thread holds for up to its switch interval (5 ms), so a poll
/// every few milliseconds would halve the speed of a simulation running beside it.
pub const POLL_INTERVAL: Duration = Duration::from_millis(50);

/// Plant steps between two looks at the clock (about 0.3 ms at 15 M steps/s).
const POLL_STEPS: usize = 4096;

/// Largest `sigma0*|v|*h/g` of one RK4 step. The bristle state relaxes at the rate
/// `sigma0*|v|/g`, fast at high speed (1.4e4 1/s at 1.4 m/s against a 10 N Coulomb
/// level on a 1e5 N/m bristle), and classic RK4 is unstable beyond 2.78 of it; a plant
/// step that would exceed this bound at its start is taken in equal pieces under it.
pub const RK4_BRISTLE_LIMIT: f64 = 1.0;

/// Plant integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Exact bristle update with v held, semi-implicit Euler for x and v.
    #[default]
    Exact,
    /// Classic RK4 on (x, v, z), a step split where the bristles would make it
    /// unstable ([`RK4_BRISTLE_LIMIT`]).
    Rk4,
}

/// Simulation options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimOptions {
    /// Plant integrator.
    pub integrator: Integrator,
    /// Plant substeps per control period (or per sample interval in open loop).
    pub substeps: usize,
    /// Initial bristle state [m].
    pub z0: f64,
    /// Initial position [m]; `None` starts at the reference (or 0).
    pub x0: Option<f64>,
    /// Initial velocity [m/s].
    pub v0: f64,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            integrator: Integrator::Exact,
            substeps: 1,
            z0: 0.0,
            x0: None,
            v0: 0.0,
        }
    }
}

/// What drives the axis.
#[derive(Debug, Clone, Copy)]
pub enum Drive<'a> {
    /// Position reference for a `pid` controller, sampled at `t`.
    Position(&'a [f64]),
    /// Speed reference for a `pi_speed` controller, sampled at `t`.
    Speed(&'a [f64]),
    /// Open loop: current command [A] at `t`, held between samples.
    Current(&'a [f64]),
}

impl<'a> Drive<'a> {
    /// The samples of the reference or command.
    fn samples(&self) -> &'a [f64] {
        match *self {
            Drive::Position(a) | Drive::Speed(a) | Drive::Current(a) => a,
        }
    }
}

/// Sampled trajectories.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimResult {
    /// Position [m].
    pub x: Vec<f64>,
    /// Velocity [m/s].
    pub v: Vec<f64>,
    /// Bristle deflection [m].
    pub z: Vec<f64>,
    /// Current [A]: actual current with a current loop, else the command.
    pub i: Vec<f64>,
    /// LuGre friction force [N].
    pub friction: Vec<f64>,
    /// Motor force acting on the mass [N].
    pub force: Vec<f64>,
}

/// `np.interp` with a forward-moving cursor (queries must not decrease).
struct Interp<'a> {
    t: &'a [f64],
    y: &'a [f64],
    j: usize,
}

impl<'a> Interp<'a> {
    #[inline(always)]
    fn at(&mut self, tq: f64) -> f64 {
        let n = self.t.len();
        if tq <= self.t[0] {
            return self.y[0];
        }
        if tq >= self.t[n - 1] {
            return self.y[n - 1];
        }
        // tq inside (t[0], t[n-1]): the cursor stops before the last sample
        while self.t[self.j + 1] <= tq {
            self.j += 1;
        }
        let (t0, t1) = (self.t[self.j], self.t[self.j + 1]);
        if tq == t0 {
            return self.y[self.j];
        }
        let y0 = self.y[self.j];
        y0 + (self.y[self.j + 1] - y0) * (tq - t0) / (t1 - t0)
    }
}

/// Simulate the axis sampled at `t`.
///
/// `keep_going` is called once the first few thousand plant steps are done, then about
/// every [`POLL_INTERVAL`] of run time; returning `false` stops the run with
/// [`Error::Interrupted`].
///
/// ```
/// use lugre::servo::{simulate, Drive, Model, SimOptions};
/// let m = Model::from_json(r#"{"axis": {"mass": 25, "force_constant": 25},
///   "friction": {"sigma0": 1e5, "sigma1": 31.62,
///     "positive": {"fc": 28.7, "fs": 60.2, "sigma2": 332.5, "vs": 0.01},
///     "negative": {"fc": 28.5, "fs": 60.1, "sigma2": 333.0, "vs": 0.01}},
///   "controller": {"type": "pid", "kp": 5e4, "ki": 5e5, "kd": 1500, "rate_hz": 10000}}"#).unwrap();
/// let t: Vec<f64> = (0..10001).map(|k| k as f64 * 1e-4).collect();
/// let xr: Vec<f64> = t.iter().map(|&s| 0.01 * s).collect();
/// let r = simulate(&m, &t, Drive::Position(&xr), &SimOptions::default(), &mut || true).unwrap();
/// assert!((r.x[10000] - 0.01).abs() < 2e-3);
/// ```
pub fn simulate(
    model: &Model,
    t: &[f64],
    drive: Drive,
    opts: &SimOptions,
    keep_going: &mut dyn FnMut() -> bool,
) -> Result<SimResult> {
    check_inputs(model, t, &drive, opts)?;
    check_resonance_step(model, t, &drive, opts)?;
    // one instance of the event loop per kind of physics and integrator
    let plain = is_plain(model);
    let t0 = t[0];
    match (plain, opts.integrator) {
        (true, Integrator::Exact) => {
            run::<false, false>(model, t, drive, opts, keep_going, &Physics::new(model, t0))
        }
        (true, Integrator::Rk4) => {
            run::<false, true>(model, t, drive, opts, keep_going, &Physics::new(model, t0))
        }
        (false, Integrator::Exact) => {
            run::<true, false>(model, t, drive, opts, keep_going, &Physics::new(model, t0))
        }
        (false, Integrator::Rk4) => {
            run::<true, true>(model, t, drive, opts, keep_going, &Physics::new(model, t0))
        }
    }
}

/// The event loop of [`simulate`] (`docs/DESIGN.md`) on checked inputs, for the
/// physics `EXTRAS` (see [`Physics`]) and the RK4 (`RK4`) or exact integrator.
fn run<const EXTRAS: bool, const RK4: bool>(
    model: &Model,
    t: &[f64],
    drive: Drive,
    opts: &SimOptions,
    keep_going: &mut dyn FnMut() -> bool,
    phys: &Physics<EXTRAS>,
) -> Result<SimResult> {
    let open_loop = matches!(drive, Drive::Current(_));
    let controller = model.controller.as_ref().filter(|_| !open_loop);
    let clock = Clock::new(t, open_loop, controller, opts.substeps);
    let tol = clock.tol;
    let reference = drive.samples();
    let mut interp = Interp {
        t,
        y: reference,
        j: 0,
    };
    let mut s = initial_state(&drive, opts);
    let mut control = controller.map(Control::new);
    let mut cmd = Command::default();
    let mut output = Output::new(t);
    let mut time = t[0];
    let mut n = 0usize;
    let mut tc = clock.update_time(0);
    let mut poll = Poll::default();
    loop {
        if time >= tc - tol {
            // controller (or open-loop command) update
            let ic = match &mut control {
                Some(c) => c.command(n, interp.at(tc), &s, phys.kf, model.axis.current_limit),
                None => reference[n],
            };
            cmd.set(ic, tc, phys.delay());
            n += 1;
            tc = clock.update_time(n);
        }
        let mut at_state = None;
        if output.due(time, tol) {
            // Record the samples due now. The friction is evaluated here, under this
            // test: inside the loop below, the compiler would hoist the evaluation (an
            // exp()) out of it and run it at every event, sample or not.
            let (g, f, row) = sample(phys, &s, &cmd, time, tol);
            // the next plant step starts from this state: it reuses (g, F)
            at_state = Some((g, f));
            output.push_due(time, tol, row);
        }
        let Some(t_out) = output.next_time() else {
            break;
        };
        // min(tc, t[k]) of two finite times (f64::min would also handle NaN)
        let next = if t_out < tc { t_out } else { tc };
        let (m, h) = clock.steps(time, next);
        let ms = phys.motor_step(h);
        for j in 0..m {
            let tj = time + j as f64 * h;
            if phys.delay().is_some() {
                cmd.release(tj, tol);
            }
            if RK4 {
                phys.step_rk4(&mut s, cmd.acting, &ms, tj);
            } else {
                phys.step_exact(&mut s, cmd.acting, &ms, tj, at_state.take());
            }
        }
        if !is_finite::<EXTRAS>(&s) {
            return Err(divergence(open_loop, time));
        }
        time = next;
        poll.after(m, keep_going)?;
    }
    Ok(output.out)
}

/// The event times of a run: the control updates (in open loop, the samples of the
/// command), the longest plant step and how close two times are to be one event.
struct Clock<'a> {
    t: &'a [f64],
    open_loop: bool,
    /// Control rate [Hz] (0 in open loop).
    rate: f64,
    /// Longest plant step [s].
    h_max: f64,
    /// Tolerance of the event times [s].
    tol: f64,
}

impl<'a> Clock<'a> {
    fn new(t: &'a [f64], open_loop: bool, ctrl: Option<&Controller>, substeps: usize) -> Self {
        let n_out = t.len();
        let rate = ctrl.map_or(0.0, |c| c.rate_hz);
        let (h_max, tol) = if open_loop {
            let span = t[n_out - 1] - t[0];
            (
                span / (n_out - 1) as f64 / substeps as f64,
                1e-9 * span / (n_out - 1) as f64,
            )
        } else {
            (1.0 / (rate * substeps as f64), 1e-9 / rate)
        };
        Clock {
            t,
            open_loop,
            rate,
            h_max,
            tol,
        }
    }

    /// The time of control update `n` (in open loop: of command sample `n`, infinite
    /// after the last).
    #[inline(always)]
    fn update_time(&self, n: usize) -> f64 {
        if self.open_loop {
            if n < self.t.len() {
                self.t[n]
            } else {
                f64::INFINITY
            }
        } else {
            // n < 2^53: the signed conversion is exact and one instruction
            self.t[0] + n as i64 as f64 / self.rate
        }
    }

    /// The plant steps from `time` to `next`: `max(1, ceil(span/h_max - 1e-6))` equal
    /// steps `(m, h)`.
    #[inline(always)]
    fn steps(&self, time: f64, next: f64) -> (usize, f64) {
        // one step in the usual case, without the call to ceil() (a libm call on
        // baseline x86-64)
        let r = (next - time) / self.h_max - 1e-6;
        let m = if r <= 1.0 {
            1
        } else {
            (r.ceil() as usize).max(1)
        };
        let h = if m == 1 {
            next - time
        } else {
            (next - time) / m as f64
        };
        (m, h)
    }
}

/// The axis at rest or as `opts` starts it, at `x0` or else at the first position
/// reference (or 0).
fn initial_state(drive: &Drive, opts: &SimOptions) -> State {
    let x = opts.x0.unwrap_or(match drive {
        Drive::Position(a) => a[0],
        _ => 0.0,
    });
    State {
        x,
        v: opts.v0,
        z: opts.z0,
        ia: 0.0,
        q: 0.0,
        fl: 0.0,
        xl: x,
        vl: opts.v0,
    }
}

/// The digital controller between its updates: the integral of the error, the
/// previous position reference and the friction feed-forward.
struct Control<'m> {
    c: &'m Controller,
    xi: f64,
    xr_prev: f64,
    ff: Option<(FeedforwardKind, LugreParams<f64>, Compensator<f64>)>,
}

impl<'m> Control<'m> {
    fn new(c: &'m Controller) -> Self {
        Control {
            c,
            xi: 0.0,
            xr_prev: 0.0,
            ff: c
                .feedforward
                .as_ref()
                .map(|f| (f.kind, f.friction, Compensator::new(f.friction))),
        }
    }

    /// The current command [A] of update `n` for the reference `xr` (position or
    /// speed) and the measured state `s`, within `limit`.
    #[inline(always)]
    fn command(&mut self, n: usize, xr: f64, s: &State, kf: f64, limit: Option<f64>) -> f64 {
        let rate = self.c.rate_hz;
        let (u, vr) = match self.c.law {
            ControlLaw::Pid { kp, ki, kd } => {
                let xr_dot = if n == 0 {
                    0.0
                } else {
                    (xr - self.xr_prev) * rate
                };
                self.xr_prev = xr;
                let e = xr - s.x;
                self.xi += e / rate;
                (kp * e + ki * self.xi + kd * (xr_dot - s.v), xr_dot)
            }
            ControlLaw::PiSpeed { kp, ki } => {
                let e = xr - s.v;
                self.xi += e / rate;
                (kp * e + ki * self.xi, xr)
            }
        };
        let f_ff = match &mut self.ff {
            None => 0.0,
            Some((FeedforwardKind::Static, p, _)) => p.stribeck(vr),
            Some((FeedforwardKind::Lugre, _, comp)) => comp.step(vr, 1.0 / rate),
        };
        let ic = (u + f_ff) / kf;
        match limit {
            Some(lim) => ic.clamp(-lim, lim),
            None => ic,
        }
    }
}

/// The current command: the latest, the one acting on the drive, and those still on
/// their way through a `delay` (time they act, value).
#[derive(Default)]
struct Command {
    latest: f64,
    acting: f64,
    queue: VecDeque<(f64, f64)>,
}

impl Command {
    /// A new command `ic` of the update at `tc`: acting at once, or `delay` later.
    #[inline(always)]
    fn set(&mut self, ic: f64, tc: f64, delay: Option<f64>) {
        self.latest = ic;
        match delay {
            None => self.acting = ic,
            Some(d) => self.queue.push_back((tc + d, ic)),
        }
    }

    /// Let the delayed commands due at `time` act.
    #[inline(always)]
    fn release(&mut self, time: f64, tol: f64) {
        while let Some(&(te, val)) = self.queue.front() {
            if te <= time + tol {
                self.acting = val;
                self.queue.pop_front();
            } else {
                break;
            }
        }
    }
}

/// `(g, F)` of the friction at the state `s` at `time`, and the row of the output:
/// `[x, v, z, i, F, force]`.
#[inline(always)]
fn sample<const EXTRAS: bool>(
    phys: &Physics<EXTRAS>,
    s: &State,
    cmd: &Command,
    time: f64,
    tol: f64,
) -> (f64, f64, [f64; 6]) {
    let fm = phys.drive_force(if phys.current_loop().is_some() {
        s.ia
    } else if phys.delay().is_some() {
        ic_eff_peek(&cmd.queue, cmd.acting, time, tol)
    } else {
        cmd.acting
    });
    let i = if phys.current_loop().is_some() {
        s.ia
    } else {
        cmd.latest
    };
    let force = phys.ripple(
        match phys.lag_w() {
            Some(_) => s.fl,
            None => fm,
        },
        s.x,
    );
    let (xl, vl) = phys.load(s);
    let sc = phys.scale(xl, time);
    let (g, f, _) = phys.friction(s.z, vl, sc, force);
    (g, f, [s.x, s.v, s.z, i, f, force])
}

/// The sampled trajectories as they are recorded.
struct Output<'a> {
    t: &'a [f64],
    /// Samples recorded so far.
    k: usize,
    out: SimResult,
}

impl<'a> Output<'a> {
    fn new(t: &'a [f64]) -> Self {
        let n = t.len();
        Output {
            t,
            k: 0,
            out: SimResult {
                x: Vec::with_capacity(n),
                v: Vec::with_capacity(n),
                z: Vec::with_capacity(n),
                i: Vec::with_capacity(n),
                friction: Vec::with_capacity(n),
                force: Vec::with_capacity(n),
            },
        }
    }

    /// Whether a sample is due at `time`.
    #[inline(always)]
    fn due(&self, time: f64, tol: f64) -> bool {
        self.k < self.t.len() && self.t[self.k] <= time + tol
    }

    /// Record `row` for every sample due at `time`.
    #[inline(always)]
    fn push_due(&mut self, time: f64, tol: f64, [x, v, z, i, f, force]: [f64; 6]) {
        while self.due(time, tol) {
            self.out.x.push(x);
            self.out.v.push(v);
            self.out.z.push(z);
            self.out.i.push(i);
            self.out.friction.push(f);
            self.out.force.push(force);
            self.k += 1;
        }
    }

    /// The time of the next sample, `None` once all are recorded.
    #[inline(always)]
    fn next_time(&self) -> Option<f64> {
        self.t.get(self.k).copied()
    }
}

/// Whether the state is finite (with the extras, the load's too).
#[inline(always)]
fn is_finite<const EXTRAS: bool>(s: &State) -> bool {
    s.x.is_finite()
        && s.v.is_finite()
        && s.z.is_finite()
        && (!EXTRAS || (s.xl.is_finite() && s.vl.is_finite()))
}

/// The error of a run that diverged at `time`.
#[cold]
fn divergence(open_loop: bool, time: f64) -> Error {
    let hint = if open_loop {
        "check the current against the mass, or give more substeps"
    } else {
        "check the controller gains against the mass and the control rate, or give \
         more substeps"
    };
    Error::Data(format!("the simulation diverged at t = {time}: {hint}"))
}

/// When a run calls its `keep_going`: after every [`POLL_STEPS`] plant steps, at most
/// once per [`POLL_INTERVAL`]. The clock is `None` until the first poll, so a run that
/// is stopped before it starts ends within its first `POLL_STEPS` steps whatever the
/// speed of the machine.
#[derive(Default)]
struct Poll {
    steps: usize,
    last: Option<Instant>,
}

impl Poll {
    /// Count `m` more plant steps; [`Error::Interrupted`] when `keep_going` says stop.
    #[inline(always)]
    fn after(&mut self, m: usize, keep_going: &mut dyn FnMut() -> bool) -> Result<()> {
        self.steps += m;
        if self.steps >= POLL_STEPS {
            self.steps = 0;
            if self.last.is_none_or(|p| p.elapsed() >= POLL_INTERVAL) {
                if !keep_going() {
                    return Err(Error::Interrupted);
                }
                self.last = Some(Instant::now());
            }
        }
        Ok(())
    }
}

/// The delayed command that would act at `time` (for reporting the motor force).
fn ic_eff_peek(queue: &VecDeque<(f64, f64)>, current: f64, time: f64, tol: f64) -> f64 {
    let mut v = current;
    for &(te, val) in queue {
        if te <= time + tol {
            v = val;
        } else {
            break;
        }
    }
    v
}

/// Simulate many models on the same input in parallel (rayon).
pub fn simulate_batch(
    models: &[Model],
    t: &[f64],
    drive: Drive,
    opts: &SimOptions,
) -> Vec<Result<SimResult>> {
    simulate_batch_with(models, t, drive, opts, &AtomicBool::new(false))
}

/// As [`simulate_batch`], stopping every run with [`Error::Interrupted`] once `cancel`
/// is set (from another thread, e.g. on Ctrl-C).
pub fn simulate_batch_with(
    models: &[Model],
    t: &[f64],
    drive: Drive,
    opts: &SimOptions,
    cancel: &AtomicBool,
) -> Vec<Result<SimResult>> {
    use rayon::prelude::*;
    models
        .par_iter()
        .map(|m| simulate(m, t, drive, opts, &mut || !cancel.load(Ordering::Relaxed)))
        .collect()
}
