"""The ``ltl-human-motion`` command line: a thin layer over the core.

Each subcommand is a module in this package that defines ``NAME``, ``HELP``,
``add_arguments(parser)`` and ``run(args) -> int``. Errors derived from
:class:`~ltl_human_motion.errors.LtlHumanMotionError` are printed as one clear message
(exit code 2), never as a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import sys
from collections.abc import Sequence

from ltl_human_motion import __version__
from ltl_human_motion.cli import interrupts
from ltl_human_motion.errors import LtlHumanMotionError
from ltl_human_motion.kernel.kept_alive import end_if_kept

SUBCOMMAND_MODULES: tuple[str, ...] = (
    "tasks", "library", "synthesize", "render", "paper", "batch", "bringup", "call", "ur_sim",
    "coexist", "demo", "study", "react",
)


def _load_subcommands() -> list:
    modules = []
    for name in SUBCOMMAND_MODULES:
        full = f"{__name__}.{name}"
        if importlib.util.find_spec(full) is not None:
            modules.append(importlib.import_module(full))
    return modules


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every available subcommand."""
    parser = argparse.ArgumentParser(
        prog="ltl-human-motion",
        description="Synthesize verified human motion from LTL task specifications.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in _load_subcommands():
        p = sub.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        module.add_arguments(p)
        p.set_defaults(_run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``ltl-human-motion``; returns the process exit code."""
    interrupts.install()
    try:
        parser = build_parser()
        args = parser.parse_args(argv)
        interrupts.check()                     # a Ctrl-C swallowed by an import
        if not hasattr(args, "_run"):
            parser.print_help()
            return 1
        code = int(args._run(args) or 0)
        interrupts.check()
        sys.stdout.flush()           # a closed pipe fails here, not at the final flush
        return code
    except LtlHumanMotionError as exc:
        print(f"ltl-human-motion {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # The reader of the output went away (`... | head`): stop quietly, as Unix tools
        # do; stdout goes to devnull so that the interpreter's final flush cannot fail.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


def run() -> None:
    """The console script: :func:`main`'s exit code, ended past the teardown where a
    broken robot interface is kept alive (:func:`.kernel.kept_alive.end_if_kept`)."""
    code = main()
    end_if_kept(code)
    sys.exit(code)


if __name__ == "__main__":
    run()
