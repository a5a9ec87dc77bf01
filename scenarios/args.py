"""Command-line arguments checked where they are read, before any simulation starts (issue 17).

:class:`Parser` is argparse with one-line errors (``error: argument --window: must be > 0 s, got '-1'``,
exit 2 through :func:`scenarios.command.command`). The ``type=`` callables below check one argument each
and say what is expected; every scenario's parser uses them, so a bad value never reaches a run.
"""
from __future__ import annotations

import argparse
import math
import os
import re
from pathlib import Path

from components.names import argparse_hint, did_you_mean

__all__ = ["Parser", "positive", "nonnegative", "count", "alpha", "conditions", "directions", "existing_file",
           "quantity_of", "key_value", "scheduler", "out_folder", "choice_list", "float_list"]

CONDITIONS = (1, 2, 3, 4)
DIRECTIONS = ("forward", "reverse")


class Parser(argparse.ArgumentParser):
    """argparse whose usage errors are one line ``error: ...`` (raised as SystemExit for the command wrapper); an
    unknown option or an invalid choice names the closest valid ones (:func:`components.names.argparse_hint`)."""

    def error(self, message):
        raise SystemExit(f"error: {argparse_hint(self, message)}")


def _named(fn, name):
    fn.__name__ = name      # argparse names a failed conversion by the type's __name__
    return fn


def _float(text: str, what: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"expected a finite number ({what}), got {text!r}")
    return x


def positive(unit: str, upper: float | None = None):
    """A number > 0 [unit] (and <= upper when given)."""
    def conv(text):
        x = _float(text, f"a number > 0 {unit}")
        if not x > 0 or (upper is not None and x > upper):
            bound = f"> 0 and <= {upper:g} {unit}" if upper is not None else f"> 0 {unit}"
            raise argparse.ArgumentTypeError(f"must be {bound}, got {text!r}")
        return x
    return _named(conv, f"number > 0 {unit}")


def nonnegative(unit: str):
    def conv(text):
        x = _float(text, f"a number >= 0 {unit}")
        if x < 0:
            raise argparse.ArgumentTypeError(f"must be >= 0 {unit}, got {text!r}")
        return x
    return _named(conv, f"number >= 0 {unit}")


def count(lo: int = 1, hi: int | None = None):
    """An integer in [lo, hi]."""
    def conv(text):
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number >= {lo}, got {text!r}") from None
        if n < lo or (hi is not None and n > hi):
            raise argparse.ArgumentTypeError(f"must be a whole number in [{lo}, {hi if hi is not None else '∞'}], "
                                             f"got {text!r}")
        return n
    return _named(conv, "whole number")


def alpha(text):
    """HHT α in [-1/3, 0] (the method's range of unconditional stability and second order)."""
    x = _float(text, "HHT alpha in [-1/3, 0]")
    if not -1.0 / 3.0 - 1e-12 <= x <= 0.0:
        raise argparse.ArgumentTypeError(f"HHT alpha must be in [-1/3, 0], got {text!r}")
    return x


def _items(text: str, what: str) -> list[str]:
    items = [x.strip() for x in str(text).split(",") if x.strip()]
    if not items:
        raise argparse.ArgumentTypeError(f"expected a comma list of {what}, got an empty list {text!r}")
    return items


def choice_list(allowed, what: str):
    """A non-empty comma list of ``allowed`` names (order kept, repeats dropped) -> comma string."""
    def conv(text):
        items = _items(text, what)
        bad = [x for x in items if x not in allowed]
        if bad:
            raise argparse.ArgumentTypeError(f"takes {what} from {', '.join(map(str, allowed))}; got {bad[0]!r}"
                                             f"{did_you_mean(bad[0], allowed)}")
        return ",".join(dict.fromkeys(items))
    return _named(conv, what)


def conditions(text):
    """Operating conditions (PARAMETERS.md): a non-empty comma list of 1, 2, 3, 4 -> comma string."""
    items = _items(text, "operating conditions 1-4")
    bad = [x for x in items if x not in {str(c) for c in CONDITIONS}]
    if bad:
        raise argparse.ArgumentTypeError(f"takes 1, 2, 3 and/or 4 (PARAMETERS.md), got {bad[0]!r}")
    return ",".join(dict.fromkeys(items))


directions = choice_list(DIRECTIONS, "directions")


def float_list(unit: str):
    """A non-empty comma list of numbers > 0 [unit]."""
    one = positive(unit)

    def conv(text):
        return [one(x) for x in _items(text, f"numbers > 0 {unit}")]
    return _named(conv, f"list of numbers > 0 {unit}")


def existing_file(text):
    p = Path(text)
    if not p.is_file():
        raise argparse.ArgumentTypeError(f"no such file {text!r}" if not p.exists() else f"{text!r} is not a file")
    if not os.access(p, os.R_OK):
        raise argparse.ArgumentTypeError(f"cannot read {text!r}")
    return str(p)


def quantity_of(dimension: str, positive_only: bool = False):
    """A quantity with its unit, e.g. "200 kW" (checked for its dimension; the string is passed on)."""
    def conv(text):
        from components.units import ParameterError, quantity, to_si

        try:
            x = to_si(quantity("value", text, dimension))
        except ParameterError as exc:
            raise argparse.ArgumentTypeError(exc.problem or f"expected a {dimension} with its unit, got {text!r}") \
                from None
        if positive_only and not x > 0:
            raise argparse.ArgumentTypeError(f"must be > 0, got {text!r}")
        return text
    return _named(conv, dimension)


def key_value(text):
    """KEY=VALUE with a non-empty key and value (parameter overrides, scene options)."""
    k, eq, v = str(text).partition("=")
    if not eq or not k.strip() or not v.strip():
        raise argparse.ArgumentTypeError(f'expects KEY=VALUE (e.g. bearing.clearance="30 um"), got {text!r}')
    return text


_ADDRESS = re.compile(r"^((tcp|tls|ucx|ws|wss)://)?[\w.\-\[\]:]+:\d{1,5}$")


def scheduler(text):
    """A Dask scheduler address, e.g. tcp://host:8786."""
    if not _ADDRESS.match(text.strip()):
        raise argparse.ArgumentTypeError(f"expected a Dask scheduler address like tcp://host:8786, got {text!r}")
    return text.strip()


def out_folder(text):
    """An output folder that exists and is writable, or can be made (its nearest existing parent is a writable
    folder)."""
    p = Path(text).expanduser()
    if p.exists() and not p.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} exists and is not a folder")
    parent = p
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise argparse.ArgumentTypeError(f"cannot make the folder {text!r}: {str(parent)!r} is a file")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise argparse.ArgumentTypeError(f"cannot write into {str(parent)!r} (permission denied)")
    return str(p)


def add_sweep_options(p, out_default: str) -> None:
    """The options every study shares: where its runs go (Dask local workers or a scheduler), what may be
    replaced or forced, progress bars, and its output folder."""
    p.add_argument("--workers", type=count(1), default=None, help="Dask local workers (default: one per core)")
    p.add_argument("--scheduler", default=None, type=scheduler, help="address of an existing Dask scheduler")
    p.add_argument("--force", action="store_true",
                   help="run although the gears collide or the recording is too large for the limit or the disk")
    p.add_argument("--overwrite", action="store_true",
                   help="replace finished results of other parameters or settings in --out (else refused)")
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--out", default=out_default, type=out_folder, help="output directory")
