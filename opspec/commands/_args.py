"""Argument types shared by the subcommands (argparse turns their errors into usage errors)."""

from __future__ import annotations

import argparse

__all__ = ["seed"]

#: numpy's SeedSequence takes non-negative integers; 2**63 keeps seeds in an SQLite integer
_MAX_SEED = 2**63 - 1


def seed(text: str) -> int:
    """A run seed: a whole number from 0 to 2**63 - 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if not 0 <= value <= _MAX_SEED:
        raise argparse.ArgumentTypeError(f"{value} is out of range: a seed is a whole number "
                                         "from 0 to 2**63 - 1")
    return value
