"""The default job (`make demo`): the forward vs reverse study at operating condition 3 (carrier
4200 r/min, 200 kW, N = 3, Z = 12), both directions in parallel on a local Dask cluster, ending with the
comparison table and the paths of its plots and cage-orbit animation.

    python -m scenarios.demo --out results/demo [paper_study options...]
"""
from __future__ import annotations

import sys

from . import paper_study
from .command import command


@command
def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if any(a in ("-h", "--help") for a in argv):
        print(__doc__)
        return paper_study.main(["--help"])
    defaults = ["--conditions", "3", "--directions", "forward,reverse", "--animate"]
    return paper_study.main(defaults + argv)


if __name__ == "__main__":
    raise SystemExit(main())
