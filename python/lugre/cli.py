"""The ``lugre`` command line.

Exit status: 0 on success, 2 for a usage problem (an option, an output that would
overwrite an input), 1 for a problem with the data or a file. Every error is one line on
stderr naming the file, row, column or option and the fix; nothing is written when a
command refuses.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .exceptions import InputError, LugreError
from .vocabulary import CURRENT_LAG, DELAY

__all__ = ["main"]


class UsageError(InputError):
    """A command-line option is unusable (exit status 2)."""

    @classmethod
    def option(cls, option: str, message: str) -> UsageError:
        return cls(f"{option}: {message}", name=option)


# --------------------------------------------------------------------------------------
# Outputs: checked before any work, written at the end, never over an input
# --------------------------------------------------------------------------------------


def _same(a: str, b: str) -> bool:
    if os.path.exists(a) and os.path.exists(b):
        return os.path.samefile(a, b)
    return os.path.abspath(a) == os.path.abspath(b)


def _check_outputs(inputs: dict[str, str | None], outputs: dict[str, str | None],
                   dirs: dict[str, str | None] | None = None) -> None:
    """Refuse outputs that would overwrite an input or each other, or cannot be written.

    ``inputs`` and ``outputs`` map the option (``--json``, ``RECORDING``) to the path;
    ``dirs`` are output directories (``--plots``).
    """
    given_in = {k: v for k, v in inputs.items() if v}
    given_out = {k: v for k, v in outputs.items() if v}
    given_dirs = {k: v for k, v in (dirs or {}).items() if v}
    for opt, out in given_out.items():
        for iopt, inp in given_in.items():
            if _same(out, inp):
                raise UsageError.option(opt, f"{out} is the {iopt} input: choose another "
                                        "output file (inputs are never overwritten)")
        parent = os.path.dirname(os.path.abspath(out))
        if not os.path.isdir(parent):
            raise UsageError.option(opt, f"cannot write {out}: the directory {parent} does "
                                    "not exist: create it first or choose another path")
        if os.path.isdir(out):
            raise UsageError.option(opt, f"{out} is a directory: give a file name")
    items = list(given_out.items()) + list(given_dirs.items())
    for a in range(len(items)):
        for b in range(a + 1, len(items)):
            if _same(items[a][1], items[b][1]):
                raise UsageError.option(items[b][0], f"{items[b][1]} is also given to "
                                        f"{items[a][0]}: give each output its own path")
    for opt, d in given_dirs.items():
        for iopt, inp in given_in.items():
            if _same(d, inp):
                raise UsageError.option(opt, f"{d} is the {iopt} input: choose another "
                                        "directory")
        if os.path.exists(d) and not os.path.isdir(d):
            raise UsageError.option(opt, f"{d} exists and is not a directory: give a "
                                    "directory for the figures")


def _number(kind: type, low: float, strict: bool, what: str) -> Any:
    """An argparse type: a finite number above ``low`` (or at least ``low``)."""
    import math

    def parse(text: str) -> Any:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number: give {what}") from None
        if not math.isfinite(value) or (value <= low if strict else value < low):
            raise argparse.ArgumentTypeError(f"{text} is out of range: give {what}")
        return value

    return parse


_POSITIVE = _number(float, 0.0, True, "a positive number")
_NONNEGATIVE = _number(float, 0.0, False, "a number >= 0")
_COUNT = _number(int, 0.0, True, "a whole number >= 1")
_COUNT0 = _number(int, 0.0, False, "a whole number >= 0")


def _columns(spec: str | None) -> str | None:
    return spec or None


def _cmd_design_static(args: argparse.Namespace) -> int:
    from .design import design_static
    from .identify import fit_static
    from .io import read_points

    _check_outputs({"POINTS": args.points}, {"--json": args.json})
    v, F = read_points(args.points)
    fit = fit_static(v, F, weighting=args.weighting)
    print(f"{args.points}: {len(v)} steady-state points; first fit:")
    print(fit.summary())
    rng = tuple(args.speed_range) if args.speed_range else None
    design = design_static(fit, target=args.target, budget=args.budget, speed_range=rng,
                           min_repeats=args.repeats, noise=args.noise)
    print(design.summary())
    if args.json:
        _write_json(args.json, design.to_dict())
        print(f"design written to {args.json}")
    return 0


def _write_json(path: str, obj: object) -> None:
    import json

    from ._atomic import atomic_write

    atomic_write(path, (json.dumps(obj, indent=2, default=_jsonable) + "\n").encode())


def _write_text(path: str, text: str) -> None:
    from ._atomic import atomic_write

    atomic_write(path, text.encode("utf-8"))


def _jsonable(o: object) -> object:
    import numpy as np

    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(f"cannot write {type(o).__name__} to JSON")


def _progress(args: argparse.Namespace) -> Any:
    from ._progress import Progress

    return Progress(enabled=None if not getattr(args, "quiet", False) else False)


def _note(msg: str) -> None:
    print(f"note: {msg}", file=sys.stderr)


def _x_unit(args: argparse.Namespace, kind: str | None) -> str:
    """The recording's position unit: ``--x-unit``, else the model's axis's (m or rad);
    a unit of the other kind of axis than the model's is refused."""
    from .readers import ROTARY_X_UNITS

    unit = getattr(args, "x_unit", None)
    if unit is None:
        return "rad" if kind == "rotary" else "m"
    if kind is not None and (unit in ROTARY_X_UNITS) != (kind == "rotary"):
        want = "rad or deg" if kind == "rotary" else "m, mm, um or cm"
        raise UsageError.option("--x-unit", f"{unit} is not a position of the model's "
                                f"{kind} axis: use {want}")
    return str(unit)


def _read(args: argparse.Namespace, path: str, option: str = "RECORDING",
          kind: str | None = None) -> Any:
    """Read a recording with the command's column mapping, unit and resampling options,
    and refuse it when its sampling has gaps or its units look wrong (``kind``: the
    model's axis, ``"linear"`` or ``"rotary"``, when a model is given)."""
    from .checks import require_plausible, resample_uniform
    from .io import read_recording

    x_unit = _x_unit(args, kind)
    try:
        with _progress(args).step(f"reading {path}"):
            rec = read_recording(path, _columns(args.columns), x_unit=x_unit)
    except InputError as e:
        if e.name in ("columns", "x_unit"):
            text = str(e).split(": ", 1)[-1]
            raise UsageError.option("--" + e.name.replace("_", "-"), text) from None
        raise
    if getattr(args, "resample", False):
        n = len(rec)
        rec = resample_uniform(rec)
        print(f"{path}: resampled: {n} samples linearly interpolated onto a uniform grid of "
              f"{len(rec)} samples, dt = {rec.dt:.6g} s")
    return require_plausible(rec, kind)


# --------------------------------------------------------------------------------------
# Commands
# --------------------------------------------------------------------------------------


#: What ``fit-static`` writes without a --model when the static step cannot tell it.
_PAPER_PLACEHOLDERS = ("axis.mass", "axis.force_constant", "friction.sigma0",
                       "friction.sigma1")


def _cmd_fit_static(args: argparse.Namespace) -> int:
    from . import units as U
    from .identify import fit_static, steady_state_points
    from .io import is_points_file, read_points
    from .model import Model, load_model, save_model

    _check_outputs({"POINTS_OR_RECORDING": args.data, "--model": args.model},
                   {"--json": args.json, "--plot": args.plot, "--html": args.html})
    base = load_model(args.model) if args.model else None
    pr = _progress(args)
    kind = base.kind if base else "linear"
    if is_points_file(args.data):
        v, F = read_points(args.data)
        print(f"{args.data}: {len(v)} steady-state points")
    else:
        kf = args.force_constant or (base.force_constant if base else None)
        with pr.step(f"finding the plateaus of {args.data}"):
            rec = _read(args, args.data, kind=base and base.kind)
            kind = rec.meta.get("axis_kind", kind)
            pts = steady_state_points(rec, kf, chunks=args.chunks)
        used = sum(p["settled"] for p in pts.plateaus)
        print(f"{args.data}: {len(pts.plateaus)} plateaus found, {used} settled and used "
              f"({int(pts.used.sum())} samples) -> {len(pts.v)} points")
        for n in pts.notes:
            print(f"  {n}")
        v, F = pts.v, pts.F
    with pr.step("fitting the Stribeck curves"):
        fit = fit_static(v, F, weighting=args.weighting)
    with U.axis(kind):
        print(fit.summary())
    axis = {}
    if args.mass:
        axis["mass"] = args.mass
    if args.force_constant:
        axis["force_constant"] = args.force_constant
    model = fit.to_model(base, **axis)
    assumed: list[str] = []
    if base is None:
        assumed = [p for p in _PAPER_PLACEHOLDERS
                   if not (p == "axis.mass" and args.mass)
                   and not (p == "axis.force_constant" and args.force_constant)]
        if assumed:
            paper = Model.paper()
            vals = {"axis.mass": f"{paper.mass:g} kg",
                    "axis.force_constant": f"{paper.force_constant:g} N/A",
                    "friction.sigma0": f"{paper.sigma0:g} N/m",
                    "friction.sigma1": f"{paper.sigma1:g} N s/m"}
            text = ", ".join(f"{p} = {vals[p]}" for p in assumed)
            _note(f"{args.json}: the static fit cannot tell {', '.join(assumed)}; the model "
                  f"holds the seed paper's values ({text}) as placeholders: give --model "
                  "BASE.json (or --mass/--force-constant) and run fit-dynamic for sigma0, "
                  "sigma1")
            d = model.to_dict()
            d["placeholders"] = {
                "parameters": assumed,
                "source": "seed paper (lugre.Model.paper())",
                "why": "steady-state friction points do not determine these; replace them "
                       "(--model, --mass, --force-constant, lugre fit-dynamic)",
            }
            model = Model.from_dict(d)
    page = None
    if args.html:
        from .html import static_fit_page

        with pr.step("rendering the HTML page"):
            page = static_fit_page(fit, v, F, model.to_dict(), source=args.data,
                                   assumed=assumed)
    save_model(model, args.json)
    print(f"model written to {args.json}")
    if args.plot:
        from .plots import static_fit_figure

        print(f"plot written to {static_fit_figure(v, F, fit, args.plot)}")
    if page is not None:
        _write_text(args.html, page)
        print(f"page written to {args.html}")
    return 0


def _cmd_fit_dynamic(args: argparse.Namespace) -> int:
    from .identify import fit_dynamic
    from .model import load_model, save_model

    _check_outputs({"RECORDING": args.recording, "--model": args.model}, {"--json": args.json})
    model = load_model(args.model)
    rec = _read(args, args.recording, kind=model.kind)
    with _progress(args).step("fitting sigma0 and sigma1 (closed-loop simulations)"):
        fit = fit_dynamic(rec, model, weighting=args.weighting, c1=args.c1, c2=args.c2,
                          scale_floor=args.resolution)
    print(fit.summary())
    save_model(fit.to_model(), args.json)
    print(f"model written to {args.json}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from .demo import run_demo

    _check_outputs({}, {}, {"--out": args.out})
    with _progress(args).step("simulating the demo"):
        run_demo(args.out)
    return 0


def _cmd_diagnose(args: argparse.Namespace) -> int:
    from .diagnosis import diagnose, write_plots
    from .diagnosis.plots import PLOT_FILES
    from .model import load_model, save_model

    plots = args.plots  # (figures only when asked: drawing them takes longer than the rest)
    inputs = {"RECORDING": args.recording, "--model": args.model, "--holdout": args.holdout}
    outputs = {"--json": args.json, "--out-model": args.out_model, "--html": args.html}
    _check_outputs(inputs, outputs, {"--plots": plots} if plots else {})
    for name in PLOT_FILES if plots else ():  # the figures' files: no input or other output
        for opt, path in {**inputs, **outputs}.items():
            if path and _same(os.path.join(plots, name), path):
                raise UsageError.option("--plots", f"{plots} would overwrite {path} ({opt}) "
                                        f"with its figure {name}: choose another directory")
    pr = _progress(args)
    model = load_model(args.model)
    rec = _read(args, args.recording, kind=model.kind)
    hold = _read(args, args.holdout, "--holdout", model.kind) if args.holdout else None
    with pr.step("diagnosing (candidate effects, joint refits, held-out checks)"):
        d = diagnose(rec, model, holdout=hold, screw_lead=args.screw_lead,
                     cutoff_hz=args.cutoff_hz)
    print(d.summary())
    report = d.to_dict()
    page = None
    if args.html:
        from .html import diagnosis_page

        with pr.step("rendering the HTML report"):
            page = diagnosis_page(report, d.data, source=args.recording,
                                  model=args.model, holdout=args.holdout,
                                  resampled=rec.meta.get("resampled"))
    _write_json(args.json, report)
    print(f"report written to {args.json}")
    if args.out_model:
        save_model(d.augmented_model(), args.out_model)
        print(f"augmented model written to {args.out_model}")
    if page is not None:
        _write_text(args.html, page)
        print(f"page written to {args.html}")
    if plots:
        with pr.step("drawing the figures"):
            files = write_plots(d, plots)
        print(f"{len(files)} plots written to {plots}/")
    return 0


def _cmd_evaluate(args: argparse.Namespace) -> int:
    from . import units as U
    from .diagnosis import evaluate
    from .diagnosis.evaluation import level_shift_text
    from .model import load_model

    _check_outputs({"RECORDING": args.recording, "--model": args.model}, {"--json": args.json})
    model = load_model(args.model)
    ev = evaluate(_read(args, args.recording, kind=model.kind), model)
    with U.axis(model.kind):
        print(f"rms {U.force_words()} residual {ev['rms_force']:.4g} {U.si('N')}, "
              f"nrmse {100 * ev['nrmse_force']:.3g} %")
        shift = level_shift_text(ev.get("level_shift"))
    if shift:
        print(f"note: {shift}")
    _write_json(args.json, ev)
    print(f"evaluation written to {args.json}")
    return 0


def _cmd_fit(args: argparse.Namespace) -> int:
    from . import units as U

    effects = [e.strip() for e in (args.effects or "").split(",") if e.strip()]
    _check_outputs({"RECORDING": args.recording}, {"--json": args.json, "--html": args.html})
    rec = _read(args, args.recording)
    with U.axis(rec.meta.get("axis_kind", "linear")):
        return _fit_and_write(args, rec, effects)


def _fit_and_write(args: argparse.Namespace, rec: Any, effects: list[str]) -> int:
    """``lugre fit`` once the recording is read, in the units of its axis."""
    from . import units as U
    from .diagnosis import evaluate, fit_inverse_dynamics, fit_model
    from .model import save_model

    if rec.F is None and args.force_constant is None:
        raise UsageError.option("--force-constant", f"{args.recording} holds the current i: "
                                f"give the {U.constant_words()} "
                                f"{'K_T' if U.is_rotary() else 'K_F'} [{U.si('N/A')}] with "
                                "--force-constant")
    kf = args.force_constant or 1.0
    pr = _progress(args)
    fit = None
    if args.no_refine:
        with pr.step("inverse dynamics (robust least squares)"):
            model = fit_inverse_dynamics(rec, mass=args.mass, force_constant=kf)
    else:
        with pr.step("fitting mass and friction to the record"
                     + (f" with {', '.join(effects)}" if effects else "")):
            model, fit = fit_model(rec, effects=effects, mass=args.mass, force_constant=kf)
    ident = model.to_dict().get("identification") or {}
    nrmse = ident.get("nrmse_force")
    if nrmse is None:
        nrmse = evaluate(rec, model)["nrmse_force"]
    print(f"{U.force_words()} residual {100 * nrmse:.2f} % of the motor {U.force_words()} "
          "(rms)" + (" after the inverse-dynamics least squares alone" if fit is None else ""))
    if fit is not None:
        _print_fit(fit, effects)
    _print_model(model, rec.F is None)
    page = None
    if args.html:
        from .html import fit_page

        with pr.step("rendering the HTML page"):
            page = fit_page(model.to_dict(), rec, source=args.recording,
                            nrmse={"fitted model": nrmse})
    save_model(model, args.json)
    print(f"model written to {args.json}")
    if page is not None:
        _write_text(args.html, page)
        print(f"page written to {args.html}")
    return 0


def _print_model(model: Any, with_constant: bool) -> None:
    """The fitted base, each number in the axis's unit."""
    from . import units as U

    for d in ("positive", "negative"):
        p = getattr(model, d)
        print(f"{d:8s} fc {p['fc']:.4g} {U.si('N')}  fs {p['fs']:.4g} {U.si('N')}  "
              f"sigma2 {p['sigma2']:.4g} {U.si('N s/m')}  vs {p['vs']:.4g} {U.si('m/s')}")
    kf_txt = (f", {U.constant_words()} {model.force_constant:.4g} "
              f"{U.si('N/A')}" if with_constant else "")
    print(f"{U.mass_words()} {model.mass:.4g} {U.si('kg')}, sigma0 {model.sigma0:.4g} "
          f"{U.si('N/m')}, sigma1 {model.sigma1:.4g} {U.si('N s/m')}{kf_txt}")


def _print_fit(fit: Any, effects: list[str]) -> None:
    """What the base fit found: the noise floor in words, the effects asked for, what
    the record leaves open."""
    from .diagnosis.fitreport import undetermined_notes

    words, far = fit.floor_words()
    print(("warning: " if far else "") + words, file=sys.stderr if far else sys.stdout)
    dg = fit.diagnosis
    if dg is not None:
        for f in dg.findings:
            print(f"{f.effect}: " + ", ".join(f"{k} {v:.4g}" for k, v in f.parameters.items()
                                               if isinstance(v, float)))
        got = {f.effect for f in dg.findings}
        for e in effects:
            if e in got or (e in (DELAY, CURRENT_LAG) and {DELAY, CURRENT_LAG} & got):
                continue
            print(f"{e}: not supported by this record (no consistent gain on held-out "
                  "stretches); left out of the model", file=sys.stderr)
    for note in undetermined_notes(fit):
        print(f"note: {note}")
    for e in fit.set_aside:
        print(f"note: {_set_aside_words(e)}, was fitted beside the base and is left out "
              "of the model: lugre diagnose names it with its evidence and its augmented "
              f"model holds it (lugre fit --effects {e['effect']} keeps it in)")


def _set_aside_words(e: dict[str, Any]) -> str:
    """What a load the fit set aside is, in words and the axis's units."""
    from . import units as U

    if e["effect"] == "drag":
        c = U.fmt(e["coefficient"], U.unit_of("drag", "coefficient"), 4)
        return (f"a {U.force_words()} growing with the square of the speed, {c} (drag)")
    if e["effect"] == "spring":
        k = U.fmt(e["stiffness"], U.unit_of("spring", "stiffness"), 4)
        x0 = U.fmt(e["x0"], U.unit_of("spring", "x0"), 4)
        return (f"a {U.force_words()} growing with the position, {k} about {x0} (spring; "
                "its rest position is where the record's standstills put it: while the "
                "axis moves, a preload and a difference of the directions' Coulomb "
                "levels look alike)")
    return (f"a {U.force_words()} following the angle, {e['torque']:.4g} {U.si('N')} at "
            f"a phase of {e['phase']:.3g} rad (gravity)")


def _cmd_paper(args: argparse.Namespace) -> int:
    import json

    from .paper import run_paper

    _check_outputs({}, {"--html": args.html}, {"--out": args.out})
    with _progress(args).step("rerunning the paper's experiments"):
        result = run_paper(args.out, seed=args.seed, monte_carlo=args.monte_carlo)
    if args.html:
        from .html import paper_page

        written = Path(args.out) / "paper.json"
        doc = json.loads(written.read_text()) if written.is_file() else result
        _write_text(args.html, paper_page(doc))
        print(f"page written to {args.html}")
    return 0


def _cmd_fleet_run(args: argparse.Namespace) -> int:
    from .fleet import run

    _check_outputs({"DIR": args.dir}, {"--db": args.db})
    summary = run(args.dir, args.db, scheduler=args.scheduler, workers=args.workers,
                  progress=_progress(args))
    print(summary.text())
    for e in summary.errors:
        print(f"  not diagnosed: {e['axis']}/{e['recording']}: {e['error']}")
    print(f"history in {args.db}: lugre fleet report --db {args.db} --html FLEET.html")
    return 0


def _cmd_fleet_report(args: argparse.Namespace) -> int:
    from .fleet import report

    _check_outputs({"--db": args.db}, {"--html": args.html, "--json": args.json},
                   {"--parquet": args.parquet})
    if args.parquet:
        out = os.path.abspath(args.parquet)
        where = out if os.path.isdir(out) else os.path.dirname(out)
        if not os.path.isdir(where):
            raise UsageError.option("--parquet", f"cannot write {args.parquet}: the directory "
                                    f"{where} does not exist: create it first")
        if not os.access(where, os.W_OK):
            raise UsageError.option("--parquet", f"cannot write into {where}: no permission: "
                                    "choose another directory")
    with _progress(args).step("assessing the fleet and writing its outputs"):
        doc = report(args.db, html=args.html, json=args.json, parquet=args.parquet)
    ranked = doc["ranking"]
    print(f"{len(ranked)} axes, {sum(1 for r in ranked if r['alarms'])} with an alarm, "
          f"{len(doc['errors'])} recordings not diagnosed")
    for a in doc["alarms"]:
        print(f"  {a['axis']}: {a['kind']}{' ' + a['effect'] if a['effect'] else ''} since "
              f"{a['since']}")
    for opt, path in (("page", args.html), ("alarms", args.json)):
        if path:
            print(f"{opt} written to {path}")
    if args.parquet:
        print(f"Parquet tables written to {args.parquet}/")
    return 0


# --------------------------------------------------------------------------------------
# Parser
# --------------------------------------------------------------------------------------


class _Parser(argparse.ArgumentParser):
    """Usage errors in one line, with where to read more (exit status 2)."""

    def error(self, message: str) -> Any:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


class _Formatter(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Defaults in the help (where there is one to state), examples kept as written."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        if action.default in (None, False) or action.default is argparse.SUPPRESS:
            return action.help
        return super()._get_help_string(action)


_EXAMPLES = {
    "demo": "lugre demo --out figures/",
    "fit-static": "lugre fit-static points.csv --json static.json --plot static.png\n"
                  "  lugre fit-static plateaus.csv --force-constant 25 --json static.json",
    "fit-dynamic": "lugre fit-dynamic closed_loop.csv --model static.json --json model.json",
    "diagnose": "lugre diagnose recording.csv --model model.json --holdout second_run.csv \\\n"
                "      --json report.json --html report.html --out-model augmented.json",
    "evaluate": "lugre evaluate recording.csv --model model.json --json eval.json",
    "fit": "lugre fit recording.csv --force-constant 25 --json model.json --html fit.html\n"
           "  lugre fit DATA_EMPS.mat --columns 'x=qm,x_ref=qg,F=gtau*vir' --json emps.json\n"
           "  lugre fit joint.csv --x-unit deg --force-constant 0.6 --json joint.json",
    "paper": "lugre paper --out paper/ --html paper.html",
    "design-static": "lugre design-static points.csv --target 0.003 --budget 96 --json design.json",
    "fleet": "lugre fleet run plant/ --db fleet.duckdb --workers 4\n"
             "  lugre fleet report --db fleet.duckdb --html fleet.html --json ALARMS.json",
}


def _add(sub: Any, name: str, help: str, common: list[argparse.ArgumentParser]) -> Any:
    return sub.add_parser(name, help=help, description=help[0].upper() + help[1:] + ".",
                          epilog="example:\n  " + _EXAMPLES[name], formatter_class=_Formatter,
                          parents=common)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand."""
    from ._version import __version__

    p = _Parser(
        prog="lugre",
        description="LuGre friction: simulate servo axes, identify friction, diagnose mismatch.",
        epilog="examples:\n  " + "\n  ".join(_EXAMPLES[k] for k in ("fit", "diagnose")),
        formatter_class=_Formatter,
    )
    p.add_argument("--version", action="version", version=f"lugre {__version__}")
    quiet = _Parser(add_help=False)
    quiet.add_argument("-q", "--quiet", action="store_true",
                       help="no progress lines on stderr (they appear only on a terminal)")
    common = [quiet]
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    d = _add(sub, "demo", "simulate the seed paper's axis (stick-slip, speed tracking) and "
             "save plots", common)
    d.add_argument("--out", default="lugre-demo", help="directory for the PNG figures")
    d.set_defaults(func=_cmd_demo)

    w: dict[str, Any] = {"choices": ["igg", "huber", "tukey", "none"], "default": "igg",
         "help": "robust weights (igg as in the seed paper; none = least squares)"}
    c: dict[str, Any] = {"default": None, "metavar": "MAP",
         "help": "column mapping for other names or units, e.g. 'x=qm,F=gtau*vir' or "
                 "'x=pos/1000'"}

    def recording_options(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--columns", **c)
        sp.add_argument("--x-unit", choices=["m", "mm", "um", "cm", "rad", "deg"],
                        default=None,
                        help="unit of the recorded positions (and speeds per second), "
                             "converted to m; rad and deg make it a rotary axis's, in rad "
                             "(default: the model's axis's unit, m without a model)")
        sp.add_argument("--resample", action="store_true",
                        help="interpolate linearly onto a uniform time grid when the "
                             "sampling has gaps (said in the output)")

    fs = _add(sub, "fit-static", "Stribeck parameters per direction from steady-state "
              "points (v,F) or a raw constant-velocity record", common)
    fs.add_argument("data", metavar="POINTS_OR_RECORDING")
    fs.add_argument("--json", required=True, metavar="MODEL.json", help="model to write")
    fs.add_argument("--model", metavar="BASE.json",
                    help="take axis, sigma0, sigma1, effects and controller from this model "
                         "(without it the seed paper's values are placeholders)")
    fs.add_argument("--force-constant", type=_POSITIVE,
                    help="K_F [N/A] for a record of currents")
    fs.add_argument("--mass", type=_POSITIVE, help="moving mass [kg] to write into the model")
    fs.add_argument("--weighting", **w)
    recording_options(fs)
    fs.add_argument("--chunks", type=_COUNT, default=3,
                    help="points per settled plateau of a raw record")
    fs.add_argument("--plot", metavar="PNG", help="write a figure of the fit")
    fs.add_argument("--html", metavar="PAGE.html", help="write a self-contained HTML page")
    fs.set_defaults(func=_cmd_fit_static)

    ds = _add(sub, "design-static", "from a first static fit, the speeds and runs per speed "
              "that reach a target precision of every Stribeck parameter", common)
    ds.add_argument("points", metavar="POINTS", help="CSV of steady-state points (v, F)")
    ds.add_argument("--json", metavar="DESIGN.json", help="write the design")
    ds.add_argument("--target", type=_POSITIVE, default=0.003,
                    help="relative standard error wanted for every parameter")
    ds.add_argument("--budget", type=int, default=96, help="most runs per direction")
    ds.add_argument("--repeats", type=int, default=3,
                    help="runs at least per chosen speed, so gross errors stay detectable")
    ds.add_argument("--speed-range", type=float, nargs=2, metavar=("LO", "HI"),
                    help="speeds the axis can hold [m/s] (default vs/50 to 40 vs)")
    ds.add_argument("--noise", type=_POSITIVE, help="force noise [N] (default: the fit's scale)")
    ds.add_argument("--weighting", **w)
    ds.set_defaults(func=_cmd_design_static)

    fd = _add(sub, "fit-dynamic", "sigma0 and sigma1 from a closed-loop record (with x_ref) "
              "under the model's controller, static sets held", common)
    fd.add_argument("recording", metavar="RECORDING")
    fd.add_argument("--model", required=True, metavar="STATIC.json",
                    help="model with the static sets and the controller")
    fd.add_argument("--json", required=True, metavar="MODEL.json", help="model to write")
    fd.add_argument("--weighting", **w)
    fd.add_argument("--c1", type=_NONNEGATIVE, default=1.0,
                    help="weight of sum(e^2) (eq. 18)")
    fd.add_argument("--c2", type=_NONNEGATIVE, default=0.0, help="weight of max|e| (eq. 18)")
    fd.add_argument("--resolution", type=_NONNEGATIVE, default=0.0,
                    help="encoder resolution [m]: lower bound of the residual scale")
    recording_options(fd)
    fd.set_defaults(func=_cmd_fit_dynamic)

    dg = _add(sub, "diagnose", "locate where the model misses the recording, name the "
              "missing physics, refit, and show the gain on held-out data", common)
    dg.add_argument("recording", metavar="RECORDING")
    dg.add_argument("--model", required=True, metavar="MODEL.json",
                    help="the model the recording is checked against")
    dg.add_argument("--holdout", metavar="RECORDING2", help="a second run for validation")
    dg.add_argument("--json", required=True, metavar="REPORT.json", help="report to write")
    dg.add_argument("--out-model", metavar="AUGMENTED.json",
                    help="the model with the findings added to its effects")
    dg.add_argument("--html", metavar="REPORT.html",
                    help="a self-contained page: verdict, findings with figures")
    dg.add_argument("--plots", metavar="DIR",
                    help="also draw the PNG figures into DIR (none without it)")
    dg.add_argument("--screw-lead", type=_POSITIVE, metavar="M",
                    help="ball-screw lead [m] (one revolution): its pitch and harmonics are "
                         "always tried for a position-periodic force (default: the model's "
                         "axis.screw_lead)")
    dg.add_argument("--cutoff-hz", type=_POSITIVE, metavar="HZ",
                    help="band of the force residual [Hz] (default: fs/25, lowered to "
                         "where the position reading's noise would dominate)")
    recording_options(dg)
    dg.set_defaults(func=_cmd_diagnose)

    ev = _add(sub, "evaluate", "rms and normalised rms of the inverse-dynamics force "
              "residual of a model on a recording", common)
    ev.add_argument("recording", metavar="RECORDING")
    ev.add_argument("--model", required=True, metavar="MODEL.json", help="the model")
    ev.add_argument("--json", required=True, metavar="EVAL.json",
                    help="evaluation to write (rms_force [N], nrmse_force)")
    recording_options(ev)
    ev.set_defaults(func=_cmd_evaluate)

    ft = _add(sub, "fit", "identify mass and LuGre friction from any recording with motion "
              "in both directions (robust inverse dynamics)", common)
    ft.add_argument("recording", metavar="RECORDING")
    ft.add_argument("--json", required=True, metavar="MODEL.json", help="model to write")
    ft.add_argument("--mass", type=_POSITIVE,
                    help="known moving mass [kg] (estimated otherwise)")
    ft.add_argument("--force-constant", type=_POSITIVE,
                    help="K_F [N/A]; needed when the recording holds the current i")
    ft.add_argument("--effects", metavar="E1,E2",
                    help="effects of the vocabulary to identify with the base from the start, "
                         "e.g. resonance,drag (each kept only if the record supports it)")
    ft.add_argument("--no-refine", action="store_true",
                    help="stop after the inverse-dynamics least squares (the start of the fit)")
    ft.add_argument("--html", metavar="PAGE.html", help="write a self-contained HTML page")
    recording_options(ft)
    ft.set_defaults(func=_cmd_fit)

    pp = _add(sub, "paper", "rerun the seed paper's experiments (Tables 1 and 2, speed "
              "tracking) beside its numbers, with PNG figures", common)
    pp.add_argument("--out", default="lugre-paper", help="directory for the figures")
    pp.add_argument("--seed", type=int, default=1, help="random seed of the synthetic data")
    pp.add_argument("--monte-carlo", type=_COUNT0, default=40,
                    help="static datasets for the Monte Carlo summary (0 to skip)")
    pp.add_argument("--html", metavar="PAGE.html", help="the tables as a self-contained page")
    pp.set_defaults(func=_cmd_paper)
    _fleet_parser(sub, common)
    return p


def _fleet_parser(sub: Any, common: list[argparse.ArgumentParser]) -> None:
    fl = _add(sub, "fleet", "diagnose every recording of a fleet of axes on a Dask cluster, "
              "keep the history, and report which axes changed, how and since when", common)
    fsub = fl.add_subparsers(dest="fleet_command", metavar="SUBCOMMAND")
    fl.set_defaults(func=lambda args: (fl.print_help(), 2)[1])
    fr = fsub.add_parser("run", parents=common, formatter_class=_Formatter,
                         help="diagnose the recordings not yet in the history",
                         description="Diagnose every recording of DIR/AXIS/ not yet in the "
                         "history against DIR/AXIS/model.json, on a Dask cluster.")
    fr.add_argument("dir", metavar="DIR", help="one folder per axis: AXIS/model.json and "
                    "its recordings (.csv, .mat, .npz, .parquet, .h5)")
    fr.add_argument("--db", required=True, metavar="FLEET.duckdb",
                    help="the history (DuckDB), created when missing")
    fr.add_argument("--scheduler", metavar="ADDRESS",
                    help="a running Dask scheduler (tcp://host:8786) whose workers read DIR")
    fr.add_argument("--workers", type=_COUNT, metavar="N",
                    help="processes of the local cluster (default: the machine's cores)")
    fr.set_defaults(func=_cmd_fleet_run)
    fp = fsub.add_parser("report", parents=common, formatter_class=_Formatter,
                         help="alarms, trends and the fleet page from the history",
                         description="The axes ranked by change, with their alarms and "
                         "trends, from the history.")
    fp.add_argument("--db", required=True, metavar="FLEET.duckdb", help="the history")
    fp.add_argument("--html", metavar="FLEET.html", help="the fleet page (one file)")
    fp.add_argument("--json", metavar="ALARMS.json", help="the alarms and the recordings "
                    "not diagnosed")
    fp.add_argument("--parquet", metavar="OUTDIR",
                    help="export each table of the history as OUTDIR/TABLE.parquet")
    fp.set_defaults(func=_cmd_fleet_report)


def _show_warning(message: Any, category: Any, filename: str, lineno: int,
                  file: Any = None, line: Any = None) -> None:
    text = " ".join(str(message).split())
    print(f"warning: {text}", file=sys.stderr)


def _run_command(args: argparse.Namespace) -> int:
    """Run the command; when an output is ``-`` (standard output) the progress and
    summary lines go to standard error, so that the output stays whole."""
    from . import _atomic

    outs = [getattr(args, k, None) for k in ("json", "html", "out_model")]
    if "-" not in outs:
        return int(args.func(args))
    saved = sys.stdout
    _atomic.STDOUT = saved
    sys.stdout = sys.stderr
    try:
        return int(args.func(args))
    finally:
        sys.stdout = saved
        _atomic.STDOUT = None


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``lugre`` command; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.showwarning = _show_warning
        try:
            return _run_command(args)
        except UsageError as e:
            print(f"lugre {args.command}: error: {e}", file=sys.stderr)
            return 2
        except (LugreError, FileNotFoundError, IsADirectoryError, PermissionError) as e:
            msg = str(e)
            if isinstance(e, OSError) and e.strerror:
                name = os.fsdecode(e.filename) if e.filename else ""
                msg = e.strerror if name in e.strerror else f"{name}: {e.strerror}"
            print(f"lugre {args.command}: error: {msg}", file=sys.stderr)
            return 1
        except BrokenPipeError:
            # the reader of our output went away (e.g. `| head`): not an error of ours
            sys.stdout = open(os.devnull, "w")  # noqa: SIM115
            return 0
        except KeyboardInterrupt:
            print(f"lugre {args.command}: interrupted", file=sys.stderr)
            return 130


if __name__ == "__main__":
    sys.exit(main())
