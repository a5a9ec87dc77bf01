"""What reading a run's results.nc costs as the figures read it: :func:`viz.results.load_run` of each file given, in
this checkout and, with ``--compare PATH``, in another (e.g. the code before a change, a ``git archive`` of it).

    python -m scenarios.bench_reads FILE [FILE ...] [--compare PATH] [--repeats 7]

Two kinds of sample per file and checkout: ``warm``, a read in a process that has read the file once already (a
study's worker drawing its next figure), and ``first``, the first read in a fresh process after ``import
viz.results`` (the reader's deferred imports of HDF5 included). The checkouts are sampled interleaved — A, B, A, B —
so a busy machine slows both alike; medians are reported with every sample. Prints a table and one JSON object last.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[2]      # the repository (this file: scenarios/numerics/bench_reads.py)

# a reader process: imports viz.results from its checkout (its working directory), then times load_run of each path
# it is sent, one line each
_READER = """
import sys, time
from viz.results import load_run
print("ready", flush=True)
for line in sys.stdin:
    t = time.perf_counter()
    load_run(line.strip())
    print(time.perf_counter() - t, flush=True)
"""


def _reader(repo: Path) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(repo)}
    p = subprocess.Popen([sys.executable, "-c", _READER], cwd=repo, env=env, stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, text=True)
    if p.stdout.readline().strip() != "ready":
        raise SystemExit(f"bench_reads: viz.results does not import in {repo}")
    return p


def _read(p: subprocess.Popen, path: Path) -> float:
    p.stdin.write(f"{path}\n")
    p.stdin.flush()
    line = p.stdout.readline()
    if not line:
        raise SystemExit(f"bench_reads: load_run({path}) failed in a reader process")
    return float(line)


def _close(p: subprocess.Popen) -> None:
    p.stdin.close()
    p.wait()


def measure(files: list[Path], repos: dict[str, Path], repeats: int) -> dict:
    """{checkout: {file: {"warm": [s...], "first": [s...]}}}, sampled interleaved."""
    out = {name: {str(f): {"warm": [], "first": []} for f in files} for name in repos}
    warm = {name: _reader(repo) for name, repo in repos.items()}
    try:
        for f in files:
            for name in repos:
                _read(warm[name], f)                      # each process reads each file once before it is timed
        for _ in range(repeats):
            for f in files:
                for name, repo in repos.items():
                    out[name][str(f)]["warm"].append(_read(warm[name], f))
                    fresh = _reader(repo)
                    out[name][str(f)]["first"].append(_read(fresh, f))
                    _close(fresh)
    finally:
        for p in warm.values():
            _close(p)
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m scenarios.bench_reads", description=__doc__.split("\n\n")[0])
    p.add_argument("files", nargs="+", type=Path, help="results.nc files (or run folders)")
    p.add_argument("--compare", type=Path, default=None, help="a second checkout to time interleaved with this one")
    p.add_argument("--repeats", type=int, default=7, help="samples of each kind per file and checkout (default 7)")
    a = p.parse_args(argv)
    if a.repeats < 1:
        p.error(f"--repeats must be >= 1, got {a.repeats}")
    for f in a.files:
        if not f.exists():
            p.error(f"no such file: {f}")
    repos = {"this": HERE, **({"compare": a.compare.resolve()} if a.compare else {})}
    out = measure([f.resolve() for f in a.files], repos, a.repeats)
    print(f"load_run per file, medians of {a.repeats} [ms] (every sample in the JSON below)")
    print(f"{'file':<50} {'checkout':<8} {'warm':>8} {'first':>8}")
    medians = {}
    for f in a.files:
        for name in repos:
            s = out[name][str(f.resolve())]
            m = {k: statistics.median(v) for k, v in s.items()}
            medians.setdefault(str(f), {})[name] = m
            print(f"{str(f)[-50:]:<50} {name:<8} {1e3 * m['warm']:8.1f} {1e3 * m['first']:8.1f}")
        if "compare" in repos:
            r = {k: medians[str(f)]["compare"][k] / medians[str(f)]["this"][k] for k in ("warm", "first")}
            print(f"{'':<50} {'ratio':<8} {r['warm']:8.2f} {r['first']:8.2f}   (compare / this)")
    print(json.dumps({"repos": {k: str(v) for k, v in repos.items()}, "samples_s": out, "medians_s": medians}))
    return 0
