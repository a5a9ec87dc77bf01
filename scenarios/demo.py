"""The default job (`make demo`): the forward vs reverse study at operating condition 3 (carrier
4200 r/min, 200 kW, N = 3, Z = 12), both directions in parallel on a local Dask cluster, ending with the
comparison table and the paths of its plots and cage-orbit animation.

    python -m scenarios.demo --out results/demo [paper_study options...]
"""
from __future__ import annotations

import sys

from . import paper_study
from .core.command import command

EXAMPLES = ["{prog}", "{prog} --out results/demo --workers 2", '{prog} --set bearing.clearance="30 um" --out results/demo_30um']


def build_parser():
    """The paper study's options, with the demo's defaults: condition 3, both directions, the animation."""
    return paper_study.build_parser("demo", out="results/demo", doc=__doc__, examples=EXAMPLES, animate=True)


@command
def main(argv=None) -> int:
    a = build_parser().parse_args(list(sys.argv[1:] if argv is None else argv))
    return paper_study.finish(paper_study.run(a))


if __name__ == "__main__":
    raise SystemExit(main())
