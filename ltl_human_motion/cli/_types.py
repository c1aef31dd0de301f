"""argparse types shared by the subcommands: a bad value is a usage error (exit 2) that
names the option, before anything runs."""

from __future__ import annotations

import argparse


def stature(text: str) -> float:
    """A body height in m within the motion library's range (1.55 to 1.95)."""
    from ltl_human_motion.motion.library import MAX_LIBRARY_STATURE, MIN_LIBRARY_STATURE
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a body height in m, got {text!r}") from None
    if not MIN_LIBRARY_STATURE <= value <= MAX_LIBRARY_STATURE:
        raise argparse.ArgumentTypeError(
            f"body height must be {MIN_LIBRARY_STATURE} to {MAX_LIBRARY_STATURE} m, got "
            f"{value:g}")
    return value


def positive(text: str) -> int:
    """A whole number >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a number >= 1, got {value}")
    return value
