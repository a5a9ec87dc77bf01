"""What a study costs end to end, as a user runs it: the seed study (4 conditions × 2 directions on 2 local
Dask workers) and `make demo`'s job, each a fresh process writing into a temporary folder, with the
kernels' first compile kept apart (a warm-up process loads or compiles them first; its time is reported
on its own).

    python -m scenarios.bench_study [--repeats 1] [--compare PATH] [--skip study|demo]

``--compare PATH``: a second checkout (e.g. the code before a change, `git worktree add`); both are run
interleaved — A, B, A, B — so a busy machine slows both alike; medians are reported with every sample.
Peak RSS is the largest of any process the runs started (getrusage of the waited-for children).
Prints a line per run and one JSON object last.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[2]      # the repository (this file: scenarios/numerics/bench_study.py)
JOBS = {
    "study": ["-m", "scenarios.paper_study", "--conditions", "1,2,3,4", "--directions", "forward,reverse",
              "--workers", "2", "--no-progress"],
    "demo": ["-m", "scenarios.demo", "--no-progress"],
}


def _timed(repo: Path, args: list[str], out: Path | None) -> tuple[float, int]:
    """(wall [s], exit code) of ``python args [--out out]`` run in checkout ``repo``."""
    env = {**os.environ, "PYTHONPATH": str(repo), "DPGT_PROGRESS": "0", "MPLBACKEND": "Agg"}
    cmd = [sys.executable, *args] + (["--out", str(out)] if out is not None else [])
    t = time.perf_counter()
    rc = subprocess.run(cmd, cwd=repo, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t
    if rc.returncode:
        print(f"bench_study: {' '.join(args)} in {repo} failed ({rc.returncode}): {rc.stderr.strip()[-500:]}",
              file=sys.stderr)
    return wall, rc.returncode


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m scenarios.bench_study", description=__doc__.split("\n\n")[0])
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--compare", type=Path, default=None, help="a second checkout to time interleaved with this one")
    p.add_argument("--skip", choices=sorted(JOBS), action="append", default=[])
    a = p.parse_args(argv)
    repos = {"this": HERE} | ({"compare": a.compare.resolve()} if a.compare else {})
    result: dict = {name: {"repo": str(r), "warm_s": _timed(r, ["-m", "scenarios.warm"], None)[0]}
                    for name, r in repos.items()}
    for _ in range(a.repeats):
        for job in (j for j in JOBS if j not in a.skip):
            for name, repo in repos.items():          # interleaved: a busy machine slows both alike
                with tempfile.TemporaryDirectory() as tmp:
                    wall, rc = _timed(repo, JOBS[job], Path(tmp) / "out")
                result[name].setdefault(f"{job}_s", []).append(wall if rc == 0 else None)
                print(f"{name} {job}: {wall:.1f} s" + ("" if rc == 0 else f" (failed, exit {rc})"), flush=True)
    for d in result.values():
        for k in [k for k in d if k.endswith("_s") and isinstance(d[k], list)]:
            ok = [x for x in d[k] if x is not None]
            d[k.replace("_s", "_median_s")] = statistics.median(ok) if ok else None
    result["peak_rss_MB"] = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    result["load_1min"] = os.getloadavg()[0]
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
