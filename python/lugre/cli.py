"""The ``lugre`` command line."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from .exceptions import LugreError

__all__ = ["main"]


def _cmd_demo(args: argparse.Namespace) -> int:
    from .demo import run_demo

    run_demo(args.out)
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
