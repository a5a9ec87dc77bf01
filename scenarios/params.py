"""Every parameter of the machine: its dotted key, value, unit, source tag and one-line meaning.

    python -m scenarios.params [--grep WORD] [--conditions C] [--direction forward|reverse] [--params FILE.toml]
                               [--set KEY=VALUE ...]
    python -m scenarios.params --reference [FILE]

The keys are the ones ``--set KEY=VALUE`` and a ``--params`` TOML file take in every command (the names of
docs/parameters.md); the source tag says where the value comes from ([paper] the source study, [derived] computed
from paper values, [assumed] an engineering estimate — its basis follows — [user] given by you). A value left
to its rule (e.g. the Palmgren contact stiffness) is shown resolved, in SI. With --params and --set the table is
that machine's, so it checks a file before a study runs. ``--reference`` writes the reference machine's parameter
reference, docs/parameters.md (Markdown, :mod:`components.parameter_reference`), instead of the table.
"""
from __future__ import annotations

import sys
import warnings
from pathlib import Path

from components.parameter_reference import reference_markdown
from components.geometry import check_design
from components.params import overrides_from_toml, parameter_rows, with_overrides
from components.presets import reference_dpgt
from components.results.io import atomic_write_text
from components.units import ParameterError

from .core import args
from .core.command import command

EXAMPLES = ["{prog}", "{prog} --grep clearance", "{prog} --grep bearing.cage --set bearing.cage.mass=\"0.05 kg\"",
            "{prog} --params my_machine.toml --grep user", "{prog} --reference"]
REFERENCE = Path(__file__).resolve().parent.parent / "docs" / "parameters.md"     # the repository's reference


def parse_args(argv):
    p = args.parser("params", __doc__, examples=EXAMPLES, out=None,
                    writes="nothing: the table goes to the screen; with --reference the Markdown reference FILE")
    p.add_argument("--grep", default=None, metavar="WORD",
                   help="only the parameters whose key, unit, source or meaning contains WORD (any case)")
    p.add_argument("--direction", default="forward", choices=["forward", "reverse"],
                   help="the carrier's direction (default forward)")
    p.add_argument("--reference", nargs="?", const=str(REFERENCE), default=None, metavar="FILE",
                   help="write the reference machine's parameter reference (Markdown) to FILE instead of the table "
                        f"(default {REFERENCE.relative_to(REFERENCE.parent.parent)})")
    args.add_shared(p, "conditions", "params", "set", conditions="3", one_condition_only=True)
    a = p.parse_args(argv)
    given = [o for o, v in (("--grep", a.grep), ("--params", a.params), ("--set", a.set)) if v] + \
            (["--conditions"] if a.conditions != 3 else []) + (["--direction"] if a.direction != "forward" else [])
    if a.reference is not None and given:
        p.error(f"--reference documents the reference machine at its defaults; it takes no {', '.join(given)}")
    return a


def rows(a) -> list[dict[str, str]]:
    """The table's rows (:func:`components.params.parameter_rows`) of the machine the options describe, those
    matching ``--grep``."""
    try:
        from_file = overrides_from_toml(Path(a.params).read_text(encoding="utf-8")) if a.params else {}
    except (ParameterError, ValueError) as exc:           # not TOML, not UTF-8
        raise SystemExit(f"error: --params {a.params}: {exc}".splitlines()[0]) from None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        params = with_overrides(reference_dpgt(int(a.conditions), a.direction), {**from_file, **args.parse_sets(a.set)})
        check_design(params)          # a machine that cannot be built is refused as a run would refuse it
    out = parameter_rows(params)
    if a.grep:
        word = a.grep.lower()
        out = [r for r in out if any(word in r[k].lower() for k in ("key", "unit", "source", "note", "meaning"))]
    return out


def table(rs: list[dict[str, str]]) -> str:
    """key, value, unit, source and meaning in aligned columns (the source's note after the meaning)."""
    if not rs:
        return ""
    w = {k: max(len(r[k]) for r in rs) for k in ("key", "value", "unit", "source")}
    lines = [f"{'key':<{w['key']}}  {'value':>{w['value']}} {'unit':<{w['unit']}}  {'source':<{w['source']}}  meaning"]
    for r in rs:
        meaning = r["meaning"] + (f" ({r['note']})" if r["note"] and r["note"] not in r["meaning"] else "")
        lines.append(f"{r['key']:<{w['key']}}  {r['value']:>{w['value']}} {r['unit']:<{w['unit']}}  "
                     f"{r['source']:<{w['source']}}  {meaning}")
    return "\n".join(lines)


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    if a.reference is not None:
        atomic_write_text(Path(a.reference), reference_markdown())
        print(f"written: {a.reference}")
        return 0
    rs = rows(a)
    if not rs:
        print(f"no parameter matches {a.grep!r}")
        return 0
    print(table(rs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
