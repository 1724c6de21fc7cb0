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
    except KeyboardInterrupt:
        print(f"lugre {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
