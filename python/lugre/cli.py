"""The ``lugre`` command line."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from .exceptions import InputError, LugreError

__all__ = ["main"]


def _guard_output(out: str | None, *inputs: str | None) -> None:
    """Refuse to write over an input: nothing the user gave is overwritten."""
    if out is None:
        return
    for i in inputs:
        if i and os.path.exists(i) and os.path.exists(out) and os.path.samefile(i, out):
            raise InputError.at("--json", f"{out} is also an input: choose another output "
                                "file (inputs are never overwritten)")


def _columns(spec: str | None) -> str | None:
    return spec or None


def _cmd_fit_static(args: argparse.Namespace) -> int:
    from .identify import fit_static, steady_state_points
    from .io import is_points_file, read_points
    from .model import load_model, save_model

    _guard_output(args.json, args.data, args.model)
    base = load_model(args.model) if args.model else None
    if is_points_file(args.data):
        v, F = read_points(args.data)
        print(f"{args.data}: {len(v)} steady-state points")
    else:
        kf = args.force_constant or (base.force_constant if base else None)
        pts = steady_state_points(args.data, kf, columns=_columns(args.columns),
                                  chunks=args.chunks)
        used = sum(p["settled"] for p in pts.plateaus)
        print(f"{args.data}: {len(pts.plateaus)} plateaus found, {used} settled and used "
              f"({int(pts.used.sum())} samples) -> {len(pts.v)} points")
        for n in pts.notes:
            print(f"  {n}")
        v, F = pts.v, pts.F
    fit = fit_static(v, F, weighting=args.weighting)
    print(fit.summary())
    axis = {}
    if args.mass:
        axis["mass"] = args.mass
    if args.force_constant:
        axis["force_constant"] = args.force_constant
    model = fit.to_model(base, **axis)
    save_model(model, args.json)
    print(f"model written to {args.json}")
    if args.plot:
        from .plots import static_fit_figure

        print(f"plot written to {static_fit_figure(v, F, fit, args.plot)}")
    return 0


def _cmd_design_static(args: argparse.Namespace) -> int:
    from .design import design_static
    from .identify import fit_static
    from .io import read_points

    _guard_output(args.json, args.points)
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


def _cmd_fit_dynamic(args: argparse.Namespace) -> int:
    from .identify import fit_dynamic
    from .model import load_model, save_model

    _guard_output(args.json, args.recording, args.model)
    model = load_model(args.model)
    fit = fit_dynamic(args.recording, model, weighting=args.weighting, c1=args.c1, c2=args.c2,
                      columns=_columns(args.columns), scale_floor=args.resolution)
    print(fit.summary())
    save_model(fit.to_model(), args.json)
    print(f"model written to {args.json}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from .demo import run_demo

    run_demo(args.out)
    return 0


def _write_json(path: str, obj: object) -> None:
    import json

    from .io import _atomic_write

    _atomic_write(path, (json.dumps(obj, indent=2, default=_jsonable) + "\n").encode())


def _jsonable(o: object) -> object:
    import numpy as np

    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(f"cannot write {type(o).__name__} to JSON")


def _cmd_diagnose(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .diagnosis import diagnose, write_plots
    from .io import read_recording
    from .model import load_model, save_model

    _guard_output(args.json, args.recording, args.model, args.holdout)
    _guard_output(args.out_model, args.recording, args.model, args.holdout)
    model = load_model(args.model)
    rec = read_recording(args.recording, _columns(args.columns))
    hold = read_recording(args.holdout, _columns(args.columns)) if args.holdout else None
    d = diagnose(rec, model, holdout=hold)
    print(d.summary())
    _write_json(args.json, d.to_dict())
    print(f"report written to {args.json}")
    if args.out_model:
        save_model(d.augmented_model(), args.out_model)
        print(f"augmented model written to {args.out_model}")
    plots = args.plots or str(Path(args.json).with_suffix("")) + "_plots"
    files = write_plots(d, plots)
    print(f"{len(files)} plots written to {plots}/")
    return 0


def _cmd_evaluate(args: argparse.Namespace) -> int:
    from .diagnosis import evaluate
    from .io import read_recording
    from .model import load_model

    _guard_output(args.json, args.recording, args.model)
    ev = evaluate(read_recording(args.recording, _columns(args.columns)), load_model(args.model))
    print(f"rms force residual {ev['rms_force']:.4g} N, nrmse {ev['nrmse_force']:.4g}")
    _write_json(args.json, ev)
    print(f"evaluation written to {args.json}")
    return 0


def _cmd_fit(args: argparse.Namespace) -> int:
    from .diagnosis import diagnose, evaluate, fit_inverse_dynamics
    from .io import read_recording
    from .model import save_model

    _guard_output(args.json, args.recording)
    rec = read_recording(args.recording, _columns(args.columns))
    if rec.F is None and args.force_constant is None:
        raise InputError.at("--force-constant", f"{args.recording} holds the current i: give "
                            "the force constant K_F [N/A] with --force-constant")
    model = fit_inverse_dynamics(rec, mass=args.mass, force_constant=args.force_constant or 1.0)
    before = evaluate(rec, model)["nrmse_force"]
    print(f"inverse dynamics (robust least squares, static friction curve): force nrmse "
          f"{100 * before:.2f} %")
    if not args.no_refine:
        # refine every base parameter with the bristle state simulated along the measured
        # velocity (the diagnosis's base re-estimation, with no extra physics)
        refined = diagnose(rec, model, candidates=[]).augmented_model()
        if args.mass:
            refined = refined.replace(axis={**refined.axis, "mass": args.mass})
        after = evaluate(rec, refined)["nrmse_force"]
        print(f"refined with the LuGre state simulated along the measured velocity: force "
              f"nrmse {100 * after:.2f} %")
        if after < before:
            model = refined
    for d in ("positive", "negative"):
        p = getattr(model, d)
        print(f"{d:8s} fc {p['fc']:.4g} N  fs {p['fs']:.4g} N  sigma2 {p['sigma2']:.4g} N s/m  "
              f"vs {p['vs']:.4g} m/s")
    print(f"mass {model.mass:.4g} kg, sigma0 {model.sigma0:.4g} N/m, sigma1 {model.sigma1:.4g} N s/m, "
          f"force constant {model.force_constant:.4g} N/A")
    from .identify import stribeck_determinacy

    for note in stribeck_determinacy(rec, model):
        print(f"note: {note}")
    save_model(model, args.json)
    print(f"model written to {args.json}")
    return 0


def _cmd_paper(args: argparse.Namespace) -> int:
    from .paper import run_paper

    run_paper(args.out, seed=args.seed, monte_carlo=args.monte_carlo)
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand."""
    p = argparse.ArgumentParser(
        prog="lugre",
        description="LuGre friction: simulate servo axes, identify friction, diagnose mismatch.",
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    d = sub.add_parser("demo", help="simulate the seed paper's axis (stick-slip, speed tracking)"
                       " and save plots")
    d.add_argument("--out", default="lugre-demo", help="directory for the PNG figures")
    d.set_defaults(func=_cmd_demo)

    w = {"choices": ["igg", "huber", "tukey", "none"], "default": "igg",
         "help": "robust weights (default: igg, as in the seed paper; none = least squares)"}
    c = {"default": None, "metavar": "MAP",
         "help": "column mapping for other names, e.g. 'x=qm,F=gtau*vir'"}
    fs = sub.add_parser("fit-static", help="Stribeck parameters per direction from "
                        "steady-state points (v,F) or a raw constant-velocity record")
    fs.add_argument("data", metavar="POINTS_OR_RECORDING")
    fs.add_argument("--json", required=True, metavar="MODEL.json", help="model to write")
    fs.add_argument("--model", metavar="BASE.json",
                    help="take axis, sigma0, sigma1, effects and controller from this model")
    fs.add_argument("--force-constant", type=float, help="K_F [N/A] for a record of currents")
    fs.add_argument("--mass", type=float, help="moving mass [kg] to write into the model")
    fs.add_argument("--weighting", **w)
    fs.add_argument("--columns", **c)
    fs.add_argument("--chunks", type=int, default=3,
                    help="points per settled plateau of a raw record (default 3)")
    fs.add_argument("--plot", metavar="PNG", help="write a figure of the fit")
    fs.set_defaults(func=_cmd_fit_static)

    ds = sub.add_parser("design-static", help="from a first static fit, the speeds and runs "
                        "per speed that reach a target precision of every Stribeck parameter")
    ds.add_argument("points", metavar="POINTS", help="CSV of steady-state points (v, F)")
    ds.add_argument("--json", metavar="DESIGN.json", help="write the design")
    ds.add_argument("--target", type=float, default=0.003,
                    help="relative standard error wanted for every parameter (default 0.003)")
    ds.add_argument("--budget", type=int, default=96, help="most runs per direction (96)")
    ds.add_argument("--repeats", type=int, default=3,
                    help="runs at least per chosen speed, so gross errors stay detectable (3)")
    ds.add_argument("--speed-range", type=float, nargs=2, metavar=("LO", "HI"),
                    help="speeds the axis can hold [m/s] (default vs/50 to 40 vs)")
    ds.add_argument("--noise", type=float, help="force noise [N] (default: the fit's scale)")
    ds.add_argument("--weighting", **w)
    ds.set_defaults(func=_cmd_design_static)

    fd = sub.add_parser("fit-dynamic", help="sigma0 and sigma1 from a closed-loop record "
                        "(with x_ref) under the model's controller, static sets held")
    fd.add_argument("recording", metavar="RECORDING")
    fd.add_argument("--model", required=True, metavar="STATIC.json")
    fd.add_argument("--json", required=True, metavar="MODEL.json")
    fd.add_argument("--weighting", **w)
    fd.add_argument("--c1", type=float, default=1.0, help="weight of sum(e^2) (eq. 18)")
    fd.add_argument("--c2", type=float, default=0.0, help="weight of max|e| (eq. 18)")
    fd.add_argument("--resolution", type=float, default=0.0,
                    help="encoder resolution [m]: lower bound of the residual scale")
    fd.add_argument("--columns", **c)
    fd.set_defaults(func=_cmd_fit_dynamic)

    dg = sub.add_parser("diagnose", help="locate where the model misses the recording, name "
                        "the missing physics, refit, and show the gain on held-out data")
    dg.add_argument("recording", metavar="RECORDING")
    dg.add_argument("--model", required=True, metavar="MODEL.json")
    dg.add_argument("--holdout", metavar="RECORDING2", help="a second run for validation")
    dg.add_argument("--json", required=True, metavar="REPORT.json")
    dg.add_argument("--out-model", metavar="AUGMENTED.json",
                    help="the model with the findings added to its effects")
    dg.add_argument("--plots", metavar="DIR", help="PNG directory (default: REPORT_plots/)")
    dg.add_argument("--columns", **c)
    dg.set_defaults(func=_cmd_diagnose)

    ev = sub.add_parser("evaluate", help="rms and normalised rms of the inverse-dynamics force "
                        "residual of a model on a recording")
    ev.add_argument("recording", metavar="RECORDING")
    ev.add_argument("--model", required=True, metavar="MODEL.json")
    ev.add_argument("--json", required=True, metavar="EVAL.json")
    ev.add_argument("--columns", **c)
    ev.set_defaults(func=_cmd_evaluate)

    ft = sub.add_parser("fit", help="identify mass and LuGre friction from any recording with "
                        "motion in both directions (robust inverse dynamics)")
    ft.add_argument("recording", metavar="RECORDING")
    ft.add_argument("--json", required=True, metavar="MODEL.json")
    ft.add_argument("--mass", type=float, help="known moving mass [kg] (estimated otherwise)")
    ft.add_argument("--force-constant", type=float,
                    help="K_F [N/A]; needed when the recording holds the current i")
    ft.add_argument("--no-refine", action="store_true",
                    help="stop after the inverse-dynamics least squares")
    ft.add_argument("--columns", **c)
    ft.set_defaults(func=_cmd_fit)

    pp = sub.add_parser("paper", help="rerun the seed paper's experiments (Tables 1 and 2, "
                        "speed tracking) beside its numbers, with PNG figures")
    pp.add_argument("--out", default="lugre-paper", help="directory for the figures")
    pp.add_argument("--seed", type=int, default=1, help="random seed of the synthetic data")
    pp.add_argument("--monte-carlo", type=int, default=40,
                    help="static datasets for the Monte Carlo summary (0 to skip)")
    pp.set_defaults(func=_cmd_paper)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``lugre`` command; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args))
    except (LugreError, FileNotFoundError, IsADirectoryError, PermissionError) as e:
        print(f"lugre {args.command}: error: {e}", file=sys.stderr)
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
