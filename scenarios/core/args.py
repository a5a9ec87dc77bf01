"""Command-line arguments checked where they are read, before any simulation starts.

:class:`Parser` is argparse with one-line errors (``error: argument --window: must be > 0 s, got '-1'``,
exit 2 through :func:`scenarios.core.command.command`). The ``type=`` callables below check one argument each
and say what is expected; every scenario's parser uses them, so a bad value never reaches a run.
"""
from __future__ import annotations

import argparse
import math
import os
import re
import tempfile
import textwrap
from pathlib import Path

from components.names import argparse_hint, did_you_mean
from components.scene import SceneOptions
from components.units import KINDS, ParameterError, quantity, to_si

from .points import parse_point

__all__ = ["Parser", "parser", "add_shared", "SHARED", "positive", "nonnegative", "count", "alpha", "conditions",
           "one_condition", "operating_point", "directions", "existing_file", "quantity_of", "key_value", "scheduler", "out_folder",
           "choice_list", "int_list", "float_list", "parse_sets", "switch_value", "scene_options", "invoked_as", "renamed",
           "GEAR_CLASS", "OIL", "QUANTITY_UNITS"]

CONDITIONS = (1, 2, 3, 4)
DIRECTIONS = ("forward", "reverse")


_INVOKED_AS: list[str] = []       # "dpgt" while scenarios.cli runs a command (its usage line then says dpgt NAME)


class invoked_as:
    """Context in which commands name themselves ``PREFIX NAME`` in their usage and examples (``dpgt``)."""

    def __init__(self, prefix: str):
        self.prefix = prefix

    def __enter__(self):
        _INVOKED_AS.append(self.prefix)

    def __exit__(self, *exc):
        _INVOKED_AS.pop()


def command_name(name: str) -> str:
    """How a user calls the scenario ``name`` now: ``dpgt NAME`` under the console command, else
    ``python -m scenarios.NAME``."""
    return f"{_INVOKED_AS[-1]} {name}" if _INVOKED_AS else f"python -m scenarios.{name}"


class Parser(argparse.ArgumentParser):
    """argparse whose usage errors are one line ``error: ...`` (raised as SystemExit for the command wrapper); an
    unknown option or an invalid choice names the closest valid ones (:func:`components.names.argparse_hint`).
    A ``prog`` of ``python -m scenarios.NAME`` reads ``dpgt NAME`` when the console command runs it."""

    def __init__(self, *a, **kw):
        prog = kw.get("prog")
        if prog and prog.startswith("python -m scenarios."):
            kw["prog"] = command_name(prog[len("python -m scenarios."):])
        super().__init__(*a, **kw)

    def error(self, message):
        raise SystemExit(f"error: {argparse_hint(self, message)}")


def _named(fn, name):
    fn.__name__ = name      # argparse names a failed conversion by the type's __name__
    return fn


# the units in which a plain number may also be given as a quantity ("10 ms", "20 kHz", "2000 rpm"): its dimension and
# pint's name of the unit
QUANTITY_UNITS = {"s": ("time", "s"), "Hz": ("frequency", "Hz"), "r/min": ("angular_velocity", "rpm")}


def _float(text: str, what: str, unit: str = "") -> float:
    """A finite number: plain (in ``unit``), or, for a unit of :data:`QUANTITY_UNITS`, a quantity with its own unit
    converted to ``unit`` ("10 ms" for seconds)."""
    try:
        x = float(text)
    except ValueError:
        if unit not in QUANTITY_UNITS:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from None
        dimension, name = QUANTITY_UNITS[unit]
        try:
            x = float(quantity("value", text, dimension).to(name).magnitude)
        except ParameterError:
            raise argparse.ArgumentTypeError(f"expected {what} or {KINDS[dimension].label} with its unit "
                                             f"(e.g. '{_EXAMPLE[unit]}'), got {text!r}") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"expected a finite number ({what}), got {text!r}")
    return x


_EXAMPLE = {"s": "10 ms", "Hz": "20 kHz", "r/min": "2000 rpm"}


def positive(unit: str, upper: float | None = None):
    """A number > 0 [unit] (and <= upper when given)."""
    def conv(text):
        x = _float(text, f"a number > 0 {unit}", unit)
        if not x > 0 or (upper is not None and x > upper):
            bound = f"> 0 and <= {upper:g} {unit}" if upper is not None else f"> 0 {unit}"
            raise argparse.ArgumentTypeError(f"must be {bound}, got {text!r}")
        return x
    return _named(conv, f"number > 0 {unit}")


def nonnegative(unit: str):
    def conv(text):
        x = _float(text, f"a number >= 0 {unit}", unit)
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
    """Operating conditions (docs/parameters.md): a non-empty comma list of 1, 2, 3, 4 -> comma string."""
    items = _items(text, "operating conditions 1-4")
    bad = [x for x in items if x not in {str(c) for c in CONDITIONS}]
    if bad:
        raise argparse.ArgumentTypeError(f"takes 1, 2, 3 and/or 4 (docs/parameters.md), got {bad[0]!r}")
    return ",".join(dict.fromkeys(items))


def _one_condition(then: str = ""):
    """One operating condition 1-4 (a command that runs one at a time): a comma list of more is refused in one
    line saying so; ``then`` ends that line (what a user does besides running it once per condition)."""
    def conv(text):
        items = _items(text, "operating conditions 1-4")
        if len(items) > 1:
            raise argparse.ArgumentTypeError(f"this command runs one condition at a time, got {text!r}; run it "
                                             f"once per condition{then}")
        return count(1, 4)(items[0])
    return _named(conv, "operating condition")


one_condition = _one_condition(" (each with its own --out)")

directions = choice_list(DIRECTIONS, "directions")


def int_list(lo: int, hi: int | None, what: str):
    """A non-empty comma list of distinct whole numbers in [lo, hi] -> list of int."""
    conv = count(lo, hi)

    def parse(text: str) -> list[int]:
        items = [x.strip() for x in text.split(",") if x.strip()]
        if not items:
            raise argparse.ArgumentTypeError(f"expected a comma list of {what}, got {text!r}")
        out = [conv(x) for x in items]
        if len(set(out)) < len(out):
            raise argparse.ArgumentTypeError(f"{what} repeat in {text!r}")
        return out
    return _named(parse, f"comma list of {what}")


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
        try:
            x = to_si(quantity("value", text, dimension))
        except ParameterError as exc:
            raise argparse.ArgumentTypeError(exc.problem or f"expected {KINDS[dimension].label} with its unit, got "
                                             f"{text!r}") \
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
    try:        # made and removed: what the folder's permissions do not tell (/proc, a read-only mount, quotas)
        os.rmdir(tempfile.mkdtemp(prefix=".dpgt-probe-", dir=parent))
    except OSError as exc:
        raise argparse.ArgumentTypeError(f"cannot make a folder in {str(parent)!r} ({exc.strerror or exc})") from None
    return str(p)


class _Given(argparse.Action):
    """Stores the value and that it was given (``DEST_given``): the default conditions stand only when no point is
    named otherwise (``--operating``, a file's points)."""

    def __call__(self, parser, namespace, values, option_string=None):
        setattr(namespace, self.dest, values)
        setattr(namespace, f"{self.dest}_given", True)


class _Renamed(argparse.Action):
    """An option's retired name: refused in one line naming the option that does its work."""

    def __init__(self, option_strings, dest, new: str = "", **kw):
        super().__init__(option_strings, dest=dest, nargs="?", default=None, help=argparse.SUPPRESS)
        self.new = new

    def __call__(self, parser, namespace, values, option_string=None):
        raise SystemExit(f"error: {option_string} is not an option of any dpgt command; use {self.new}")


def renamed(p, *old: str, new: str) -> None:
    """Refuse the retired option names ``old`` of the parser ``p`` in one line naming ``new`` (hidden from --help)."""
    p.add_argument(*old, action=_Renamed, new=new, dest="retired_" + old[0].lstrip("-").replace("-", "_"))


# the one name of each option that several commands take (refused spellings: renamed)
GEAR_CLASS = "--gear-class"      # ISO 1328-1 flank tolerance class of the gears
OIL = "--oil"                    # ISO VG grade of the oil


def operating_point(text):
    """One ``--operating`` point (scenarios.core.points.parse_point), checked where it is read; the text is passed on."""
    try:
        parse_point(text)
    except ParameterError as exc:
        raise argparse.ArgumentTypeError(exc.problem or str(exc)) from None
    return text


# ---------------------------------------------------------------------------------------------------------------
# the shared command grammar: one definition of every option the commands share
# ---------------------------------------------------------------------------------------------------------------
SHARED = {
    "conditions": (("--conditions",), dict(type=conditions, metavar="C[,C...]",
                                            help="comma list of operating conditions 1-4 (docs/parameters.md; default "
                                                 "{conditions})")),
    "operating": (("--operating",), dict(action="append", default=[], type=operating_point, metavar='"[NAME:] SPEED, LOAD"',
                                         help='your own operating point, e.g. --operating "cruise: 1500 rpm, 120 kW" '
                                              '(repeatable; items: a speed, "sun" for the sun\'s, a power or a torque, '
                                              'forward/reverse, "oil 80 degC"; or [[operating_point]] tables in '
                                              '--params; README: Operating points)')),
    "params": (("--params",), dict(default=None, type=existing_file, metavar="FILE.toml",
                                   help="TOML file of parameter overrides, dotted keys as `dpgt params` lists them")),
    "set": (("--set",), dict(action="append", default=[], metavar="KEY=VALUE", type=key_value,
                             help='override a parameter, e.g. --set bearing.clearance="30 um" (repeatable; keys, '
                                  'values, units and sources: `dpgt params`)')),
    "out": (("--out",), dict(type=out_folder, metavar="DIR", help="output folder (default {out})")),
    "overwrite": (("--overwrite",), dict(action="store_true",
                                         help="replace finished results of other parameters or settings in --out "
                                              "(else refused)")),
    "force": (("--force",), dict(action="store_true",
                                 help="run although the gears collide or the recording is too large for the limit "
                                      "or the disk")),
    "no-progress": (("--no-progress",), dict(action="store_true",
                                             help="no progress bars (a log file or a pipe gets plain lines anyway)")),
    "workers": (("--workers",), dict(type=count(1), default=None, metavar="N",
                                     help="runs at a time on a local Dask cluster (default: one per core, at most "
                                          "one per run)")),
    "threads": (("--threads",), dict(type=count(1), default=1, metavar="N",
                                     help="threads of each run's compiled engine (default 1; the same results on any "
                                          "number; pays only when the runs at a time times N leave cores idle: "
                                          "docs/numerics.md §5 Threads)")),
    "scheduler": (("--scheduler",), dict(default=None, type=scheduler, metavar="ADDR",
                                         help="address of an existing Dask scheduler, e.g. tcp://host:8786 "
                                              "(default: a local cluster)")),
}
SHARED_TITLE = "shared options (the same name, default and meaning in every dpgt command)"
SWEEP = ("conditions", "operating", "params", "set", "out", "overwrite", "force", "no-progress", "workers", "threads",
         "scheduler")


# the default --conditions of the commands (the source's fastest loaded condition); a command whose default differs
# says why in its --help (add_shared's conditions_why)
DEFAULT_CONDITIONS = "3"
DEFAULT_CONDITIONS_WHY = "condition 3, 4200 rpm and 200 kW: the source's fastest loaded condition"


def add_shared(p, *names: str, out: str | None = None, conditions: str | None = None,
               one_condition_only: bool = False, conditions_why: str | None = None) -> None:
    """Add the shared options ``names`` (keys of :data:`SHARED`; default: all of them) to the parser ``p``, with
    one help text each. ``out``: the command's default output folder; ``conditions``: its default conditions
    (other than :data:`DEFAULT_CONDITIONS` only with ``conditions_why``, said in the help);
    ``one_condition_only``: the command runs one condition (``--condition`` then stays as the former spelling)."""
    if "conditions" in (names or SWEEP) and conditions != DEFAULT_CONDITIONS and not conditions_why:
        raise ValueError(f"{p.prog}: default --conditions {conditions} differs from {DEFAULT_CONDITIONS}: say why "
                         f"(conditions_why)")
    g = p.add_argument_group(SHARED_TITLE)
    for name in names or SWEEP:
        flags, kw = SHARED[name]
        kw = dict(kw)
        if name == "out":
            kw["default"] = out
            kw["help"] = kw["help"].format(out=out)
        elif name == "conditions":
            kw["default"] = conditions
            if one_condition_only:
                flags = (*flags, "--condition")
                writes = "out" in (names or SWEEP)          # a command without --out: no advice about it
                kw.update(type=one_condition if writes else _one_condition(), metavar="C", action=_Given,
                          help=f"operating condition 1-4, one (docs/parameters.md; default {conditions}, "
                               f"{DEFAULT_CONDITIONS_WHY}; --condition: the former spelling, still accepted)")
                p.set_defaults(conditions_given=False)
            else:
                kw["help"] = kw["help"].format(conditions=conditions) + (
                    f"; {conditions_why}" if conditions_why else f"; {DEFAULT_CONDITIONS_WHY}")
                kw["action"] = _Given            # a study tells a default from a choice (points: README)
                p.set_defaults(conditions_given=False)
        g.add_argument(*flags, **kw)


def parser(name: str, doc: str, *, examples: list[str], writes: str, out: str | None) -> Parser:
    """The parser of the scenario ``name``: its description (the first paragraph of ``doc``), and after the
    options its examples (``{prog}`` stands for the command), what it writes and its default output folder."""
    prog = command_name(name)
    ex = "\n".join(f"  {e.format(prog=prog)}" for e in examples)
    wrapped = "\n".join("  " + line for line in _wrap(writes))
    where = f"writes (into --out, default {out}):" if out else "writes:"
    return Parser(prog=f"python -m scenarios.{name}", description=" ".join(doc.strip().split("\n\n")[0].split()),
                  epilog=f"examples:\n{ex}\n\n{where}\n{wrapped}" + (f"\n\ndefault --out: {out}" if out else ""),
                  formatter_class=argparse.RawDescriptionHelpFormatter)


def _wrap(text: str, width: int = 100) -> list[str]:
    return textwrap.wrap(" ".join(text.split()), width - 2)


# ---------------------------------------------------------------------------------------------------------------
# values of repeated KEY=VALUE options
# ---------------------------------------------------------------------------------------------------------------
def parse_sets(items: list[str]) -> dict:
    """``--set``/``--option`` items KEY=VALUE -> {key: value}; quotes around a value dropped, whole numbers as int
    (counts: planets, rollers)."""
    out = {}
    for it in items:
        if "=" not in it:
            raise SystemExit(f"error: --set expects KEY=VALUE (e.g. bearing.clearance=\"30 um\"), got {it!r}")
        k, v = it.split("=", 1)
        v = v.strip().strip('"').strip("'")
        out[k.strip()] = int(v) if v.lstrip("+-").isdigit() else v   # counts (planets, rollers) are integers
    return out


def switch_value(v: str):
    """A scene switch's value: true/yes/on/1 and false/no/off/0 as booleans, anything else as given."""
    lv = v.strip().lower()
    if lv in ("true", "yes", "on", "1"):
        return True
    if lv in ("false", "no", "off", "0"):
        return False
    return v


def scene_options(items: list[str]):
    """``--option KEY=VALUE`` items -> :class:`components.scene.SceneOptions`."""
    return SceneOptions.from_dict({k: switch_value(str(v)) for k, v in parse_sets(items).items()})
