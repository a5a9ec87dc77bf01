"""What a study costs end to end, as a user runs it: the seed study (4 conditions × 2 directions on 2 local
Dask workers) and `make demo`'s job, each a fresh process writing into a temporary folder, with the
kernels' first compile kept apart (a warm-up process loads or compiles them first; its time is reported
on its own).

    python -m scenarios.bench_study [--repeats 1] [--compare PATH] [--skip study|demo] [--profile]
    python -m scenarios.bench_study --fresh-clone [--skip demo]

``--compare PATH``: a second checkout (e.g. the code before a change, `git worktree add`); both are run
interleaved — A, B, A, B — so a busy machine slows both alike; medians are reported with every sample, and the
before/after ratio of each pair run back to back.

``--profile``: where each job's wall time went, from what the study writes when ``DPGT_TIMING`` names a file
(:data:`scenarios.core.study.TIMING_ENV`: its checks, Dask phases, each run's span on its worker, the report's
steps) and each run's ``timing`` in its summary.json (engine, statistics, recording, set-up, kernels); the time
outside the study's own clock is the interpreter's start, the imports and the exit. On Dask the runs' parts are
worker-seconds shared out over the workers, so the rows add up to the wall time. Then the wall time against its
target (:func:`target`): ``1.15 × (the work / workers) + the runs' tail``, the work the integration steps' or the runs'
worker-seconds, the tail measured or bounded.

Memory: each run's own peak resident memory (``timing.peak_rss_MB`` of its summary.json: the worker's high-water
mark reset when the run starts), max and median over the runs; the study process's own peak; and the largest of the
job's process and the descendants it reaped (``wait4``), the only one a checkout without per-run timing gives.

``--fresh-clone``: ``git clone`` of this checkout's HEAD (uncommitted changes are not in it) into a temporary
folder, its virtual environment made by its own Makefile (``make install``: venv, pip, ``pip install -e
.[test]``; wheels from ``PIP_FIND_LINKS`` if set) with the interpreter found on PATH outside any active venv, an
empty ``NUMBA_CACHE_DIR``; then timed apart: the install, the kernels' compile (``make warm``) and the demo's job
(``python -m scenarios.demo``, what ``make demo`` runs after warm). Their sum is a fresh clone's ``make demo``.

Prints a line per run, the tables asked for, and one JSON object last.
"""
from __future__ import annotations

import argparse
import glob
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from scenarios.core.memory import maxrss_kb
from scenarios.core.study import TIMING_ENV

HERE = Path(__file__).resolve().parents[2]      # the repository (this file: scenarios/numerics/bench_study.py)
JOBS = {
    "study": ["-m", "scenarios.paper_study", "--conditions", "1,2,3,4", "--directions", "forward,reverse",
              "--workers", "2", "--no-progress"],
    "demo": ["-m", "scenarios.demo", "--no-progress"],
}
# a run's timing parts (summary.json "timing", scenarios.core.runner) -> the profile's group and words
RUN_PARTS = {
    "engine_s": ("engine", "engine: the integration steps"),
    "statistics_s": ("statistics", "statistics: the observer on every block, the summary"),
    "recording_s": ("recording", "recording: sampling at 25 kHz, its chunks"),
    "results_write_s": ("recording", "recording: writing results.nc"),
    "scene_s": ("set-up", "set-up: scene, statistics, recorder"),
    "runner_setup_s": ("set-up", "set-up: engine path (compiled system, LU pattern), binding"),
    "kernels_s": ("kernels", "loading (or compiling) the kernels: engine, outputs, accumulators"),
    "checkpoints_s": ("other", "checkpoints"),
    "other_s": ("other", "run: the rest (progress, step statistics, warnings, summary.json)"),
}


def _rusage_run(cmd: list[str], cwd: Path, env: dict, log: Path) -> tuple[float, int, float]:
    """(wall [s], exit code, peak RSS [MiB] of the process and the descendants it reaped) of ``cmd``; its stderr
    goes to ``log``."""
    with open(log, "w") as err:
        t = time.perf_counter()
        p = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=err)
        _, status, ru = os.wait4(p.pid, 0)
        wall = time.perf_counter() - t
    p.returncode = os.waitstatus_to_exitcode(status)
    return wall, p.returncode, maxrss_kb(ru) / 1024.0


def _env(repo: Path, **extra) -> dict:
    return {**os.environ, "PYTHONPATH": str(repo), "DPGT_PROGRESS": "0", "MPLBACKEND": "Agg", **extra}


def _job(repo: Path, args: list[str], tmp: Path, python: str = sys.executable, env: dict | None = None) -> dict:
    """One job in a fresh process: its wall time, exit code, the study's timing file and its runs' summaries."""
    out, timing = tmp / "out", tmp / "timing.json"
    env = {**(env or _env(repo)), TIMING_ENV: str(timing)}
    wall, rc, tree_mb = _rusage_run([python, *args, "--out", str(out)], repo, env, tmp / "stderr.txt")
    if rc:
        err = (tmp / "stderr.txt").read_text(errors="replace").strip()[-800:]
        print(f"bench_study: {' '.join(args)} in {repo} failed ({rc}): {err}", file=sys.stderr)
    runs = {}
    for f in sorted(glob.glob(str(out / "*" / "summary.json"))):
        try:
            runs[Path(f).parent.name] = json.loads(Path(f).read_text()).get("timing")
        except (OSError, ValueError):
            pass
    study = json.loads(timing.read_text()) if timing.exists() else None
    return {"wall_s": wall, "rc": rc, "tree_peak_rss_MB": tree_mb, "study": study, "runs": runs}


def memory(job: dict) -> dict:
    """Peak RSS per run (max, median over the runs), the study process's own, the job's process tree's largest."""
    peaks = [r["peak_rss_MB"] for r in job["runs"].values() if r and "peak_rss_MB" in r]
    return {"run_peak_rss_max_MB": max(peaks) if peaks else None,
            "run_peak_rss_median_MB": statistics.median(peaks) if peaks else None,
            "runs_with_peak": len(peaks),
            "study_process_peak_rss_MB": (job["study"] or {}).get("peak_rss_MB"),
            "largest_process_MB": job["tree_peak_rss_MB"]}


def profile(job: dict) -> list[tuple[str, str, float]]:
    """(group, part, wall seconds) of one job, adding up to its wall time (module docstring: --profile)."""
    W, T = job["wall_s"], job["study"]
    if T is None:
        return []
    sw, rows = T["sweep"], []
    add = lambda g, what, s: rows.append((g, what, float(s)))
    add("python", "interpreter start, imports, exit", W - T["total_s"])
    add("checks", "parameters, designs, folders, reuse check", T["checks_s"] + T["prepare_s"] + sw.get("reuse_check_s", 0))
    behind = "cluster_close_wait_s" in sw        # the cluster closed behind the report: only the wait for it is wall time
    close = sw.get("cluster_close_wait_s", 0.0) if behind else sw.get("cluster_close_s", 0.0)
    if sw.get("dask"):
        add("dask", "cluster start: Dask imported, scheduler and 2 worker processes", sw["cluster_start_s"])
        add("dask", "cluster close, waited for after the report (it closes behind the report)" if behind
            else "cluster close", close)
    R, n = sw.get("runs_s", 0.0), max(int(sw.get("workers", 1)), 1)
    spans = {k: v for k, v in T["runs"].items() if v}
    by_pid: dict[int, list] = {}
    for k, v in spans.items():
        by_pid.setdefault(v["pid"], []).append((v["start_unix_s"], v["end_unix_s"], k))
    first = gaps = tail = 0.0
    for pid, sp in by_pid.items():
        sp.sort()
        first += sp[0][0] - sw["runs_start_unix_s"]
        gaps += sum(b[0] - a[1] for a, b in zip(sp, sp[1:]))
        tail += sw["runs_end_unix_s"] - sp[-1][1]
    tail += (n - len(by_pid)) * R           # a worker that ran nothing waited the whole phase
    drawn = _beside_in_phase(sw, by_pid)
    first, gaps, tail = first - drawn["first"], gaps - drawn["gaps"], tail - drawn["tail"]
    parts = dict.fromkeys(RUN_PARTS, 0.0)
    outside = 0.0
    for k, v in spans.items():
        t = job["runs"].get(k) or {}
        for p in RUN_PARTS:
            parts[p] += t.get(p, 0.0)
        outside += (v["end_unix_s"] - v["start_unix_s"]) - t.get("total_s", 0.0)
    for p, (g, what) in RUN_PARTS.items():
        add(g, what, parts[p] / n)
    add("other", "a run's case outside the runner (parameters, lock, folder checks)", outside / n)
    add("figures", "figures beside the runs, drawn while runs were on (their share of a worker)",
        sum(drawn.values()) / n)
    add("figures", "figures beside the runs, waited for after the last run", sw.get("beside_tail_s", 0.0))
    if sw.get("dask"):
        add("dask", "a worker's first task: the imports, transfer, start", first / n)
        add("dask", "between a worker's tasks: scheduling, transfer", gaps / n)
        add("dask", "idle at the end: waiting for the other worker's last run", tail / n)
    else:
        add("other", "between runs (in-process)", (first + gaps + tail) / n)
    steps = T.get("steps_s", {})
    for what, s in steps.items():
        add("study I/O", f"report: {what}", s)
    add("study I/O", "report: relative lives into each summary.json, headline tables", T["report_s"] - sum(steps.values()))
    # the close: inside the sweep, or after the report (the wait for it; total_s holds it, report_s does not)
    sweep_rest = (T["sweep_s"] - sw.get("reuse_check_s", 0) - sw.get("cluster_start_s", 0) - R
                  - (0.0 if behind else close) - sw.get("beside_tail_s", 0.0))
    add("other", "the study's rest (sweep bookkeeping, epilogue)", T["total_s"] - T["checks_s"] - T["prepare_s"]
        - T["sweep_s"] - T["report_s"] - (close if behind else 0.0) + sweep_rest)
    return rows


def target(job: dict) -> dict | None:
    """The study's wall time against its target ``1.15 W / n + tail``: the work ``W`` shared over the ``n`` workers,
    15 % on top, plus the tail of the runs' schedule. Two readings of ``W``:

    * ``engine``: the integration steps alone (the runs' ``engine_s``), the strict one;
    * ``runs``: the runs' worker-seconds, each run's span on its worker (its engine, statistics, recording,
      set-up: the work only the runs do) — the accounting of "its eight runs are 123 worker-seconds = 62 s on the two
      workers".

    and two of the tail: ``measured``, the time the last run went on after the first worker ran out of runs (the
    runs' own schedule, the pieces beside them left out; a worker that ran none ran out at the start), and
    ``bound``, ``(1 − 1/n) p_max`` with ``p_max`` the longest run: the most a greedy schedule of the runs can leave one
    going alone (Graham's bound for list scheduling). ``ratio`` = wall / target (≤ 1: met); the keys
    ``"engine, measured"``, ``"runs, measured"``, ``"runs, bound"``. None for a job without a sweep's timing."""
    T = job["study"]
    if T is None:
        return None
    spans = {k: v for k, v in T["runs"].items() if v}
    if not spans:
        return None
    sw = T["sweep"]
    n = max(int(sw.get("workers", 1)), 1)
    walls = {k: v["end_unix_s"] - v["start_unix_s"] for k, v in spans.items()}
    last: dict[int, float] = {}
    for v in spans.values():
        last[v["pid"]] = max(last.get(v["pid"], -float("inf")), v["end_unix_s"])
    ran_out = min(last.values()) if len(last) >= n else sw.get("runs_start_unix_s", min(last.values()))
    tails = {"measured": max(last.values()) - ran_out, "bound": (1.0 - 1.0 / n) * max(walls.values())}
    works = {"engine": sum((job["runs"].get(k) or {}).get("engine_s", 0.0) for k in spans), "runs": sum(walls.values())}
    out = {"wall_s": job["wall_s"], "workers": n, "longest_run_s": max(walls.values()), "tails_s": tails,
           "works_s": works}
    for w, tl in (("engine", "measured"), ("runs", "measured"), ("runs", "bound")):
        tgt = 1.15 * works[w] / n + tails[tl]
        out[f"{w}, {tl}"] = {"target_s": tgt, "ratio": job["wall_s"] / tgt}
    return out


def target_line(name: str, jobs: list[dict]) -> str:
    """One line per job and reading: wall, target and their ratio (:func:`target`)."""
    words = {"engine": "the integration steps' worker-seconds", "runs": "the runs' worker-seconds",
             "measured": "the runs' measured tail", "bound": "the longest run's tail bound (1 − 1/n) p_max"}
    out = []
    for j in jobs:
        t = target(j)
        for key in (("engine, measured", "runs, measured", "runs, bound") if t is not None else ()):
            w, tl = key.split(", ")
            r, n = t[key], t["workers"]
            out.append(f"{name}: wall {t['wall_s']:.1f} s against 1.15 × {t['works_s'][w]:.1f} / {n} + "
                       f"{t['tails_s'][tl]:.1f} = {r['target_s']:.1f} s ({words[w]} over the workers, 15 % on top, "
                       f"{words[tl]}): ratio {r['ratio']:.2f}" + (" — met" if r["ratio"] <= 1 else " — not met"))
    return "\n".join(out)


def _beside_in_phase(sw: dict, by_pid: dict) -> dict[str, float]:
    """Wall seconds of the work beside the runs (``sweep.beside_spans``) inside the runs' phase, by where it fell on
    its process's timeline: before that process's first run, between its runs, or after its last one (a process
    that ran no run: after). The profile moves them out of the idle rows they would otherwise be counted in."""
    lo, hi = sw.get("runs_start_unix_s"), sw.get("runs_end_unix_s")
    out = {"first": 0.0, "gaps": 0.0, "tail": 0.0}
    if lo is None or hi is None:
        return out
    for span in sw.get("beside_spans", []):
        a, b = max(span["start_unix_s"], lo), min(span["end_unix_s"], hi)
        if b <= a:
            continue
        runs = by_pid.get(span["pid"])
        mid = 0.5 * (a + b)
        where = ("tail" if not runs or mid >= runs[-1][1] else "first" if mid <= runs[0][0] else "gaps")
        out[where] += b - a
    return out


def profile_table(name: str, jobs: list[dict]) -> str:
    """Markdown table of :func:`profile` summed over ``jobs`` (repeats), grouped, with shares of the wall time."""
    total = sum(j["wall_s"] for j in jobs)
    acc: dict[tuple[str, str], float] = {}
    for j in jobs:
        for g, what, s in profile(j):
            acc[(g, what)] = acc.get((g, what), 0.0) + s
    if not acc:
        return f"{name}: no profile (the checkout writes no timing)"
    groups: dict[str, float] = {}
    for (g, _), s in acc.items():
        groups[g] = groups.get(g, 0.0) + s
    k = len(jobs)
    lines = [f"{name}: wall {total / k:.1f} s (mean of {k}); parts in s per job and % of the wall time",
             "| group | part | s | % |", "|---|---|---|---|"]
    for g in sorted(groups, key=groups.get, reverse=True):
        lines.append(f"| **{g}** | | **{groups[g] / k:.1f}** | **{100 * groups[g] / total:.1f}** |")
        for (gg, what), s in sorted(acc.items(), key=lambda x: -x[1]):
            if gg == g:
                lines.append(f"| | {what} | {s / k:.2f} | {100 * s / total:.1f} |")
    return "\n".join(lines)


def compare_runs(a, repos: dict[str, Path]) -> dict:
    result: dict = {}
    for name, r in repos.items():
        with tempfile.TemporaryDirectory() as tmp:
            wall, rc, _ = _rusage_run([sys.executable, "-m", "scenarios.warm"], r, _env(r), Path(tmp) / "err")
        result[name] = {"repo": str(r), "warm_s": wall if rc == 0 else None, "jobs": {}}
        print(f"{name} warm: {wall:.1f} s", flush=True)
    for _ in range(a.repeats):
        for job in (j for j in JOBS if j not in a.skip):
            for name, repo in repos.items():          # interleaved: a busy machine slows both alike
                with tempfile.TemporaryDirectory() as tmp:
                    d = _job(repo, JOBS[job], Path(tmp))
                d["load_1min"] = os.getloadavg()[0]
                d["memory"] = memory(d)
                result[name]["jobs"].setdefault(job, []).append(d)
                m = d["memory"]
                mem = (f"; run peak RSS max {m['run_peak_rss_max_MB']:.0f} / median {m['run_peak_rss_median_MB']:.0f} MB"
                       f" over {m['runs_with_peak']} runs" if m["runs_with_peak"] else "")
                print(f"{name} {job}: {d['wall_s']:.1f} s" + ("" if d["rc"] == 0 else f" (failed, exit {d['rc']})")
                      + f" (load {d['load_1min']:.1f}{mem}; largest process {m['largest_process_MB']:.0f} MB)", flush=True)
    return result


def summarise(result: dict, names: list[str]) -> dict:
    out = {}
    for name in names:
        o = out[name] = {"repo": result[name]["repo"], "warm_s": result[name]["warm_s"]}
        for job, ds in result[name]["jobs"].items():
            ok = [d["wall_s"] for d in ds if d["rc"] == 0]
            o[f"{job}_s"] = [d["wall_s"] if d["rc"] == 0 else None for d in ds]
            o[f"{job}_median_s"] = statistics.median(ok) if ok else None
            o[f"{job}_memory"] = [d["memory"] for d in ds]
            o[f"{job}_load_1min"] = [d["load_1min"] for d in ds]
    if "compare" in names:
        for job in result["this"]["jobs"]:
            pairs = [b / a for a, b in zip(out["this"][f"{job}_s"], out["compare"][f"{job}_s"]) if a and b]
            out[f"{job}_before_over_after"] = pairs
            out[f"{job}_before_over_after_median"] = statistics.median(pairs) if pairs else None
    return out


def _outside_venv_env(extra: dict) -> dict:
    """The environment without an active virtual environment or this checkout on the path (a fresh machine's)."""
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME")}
    venv = os.environ.get("VIRTUAL_ENV")
    if venv:
        env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep)
                                      if not Path(p).resolve().is_relative_to(Path(venv).resolve()))
    return {**env, "DPGT_PROGRESS": "0", "MPLBACKEND": "Agg", **extra}


def fresh_clone(a) -> dict:
    """Clone, install (make install), compile (make warm), demo: each timed apart (module docstring)."""
    tmp = Path(tempfile.mkdtemp(prefix="bench_fresh_"))
    try:
        repo, cache = tmp / "repo", tmp / "numba_cache"
        cache.mkdir()
        head = subprocess.run(["git", "-C", str(HERE), "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(HERE), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
        print(f"fresh clone of {HERE} at {head[:10]}" + (" (uncommitted changes are not in it)" if dirty else ""),
              flush=True)
        t = time.perf_counter()
        subprocess.run(["git", "clone", "--quiet", str(HERE), str(repo)], check=True)
        out = {"commit": head, "clone_s": time.perf_counter() - t, "load_1min": [os.getloadavg()[0]]}
        env = _outside_venv_env({"NUMBA_CACHE_DIR": str(cache)})
        for step, cmd in (("install", ["make", "install"]), ("warm", ["make", "warm"])):
            wall, rc, _ = _rusage_run(cmd, repo, env, tmp / f"{step}.err")
            out[f"{step}_s"], out["load_1min"] = wall, out["load_1min"] + [os.getloadavg()[0]]
            print(f"fresh clone {' '.join(cmd)}: {wall:.1f} s" + ("" if rc == 0 else f" (failed, exit {rc})"), flush=True)
            if rc:
                print((tmp / f"{step}.err").read_text(errors="replace")[-1500:], file=sys.stderr)
                return out
        out["python"] = subprocess.run([str(repo / ".venv/bin/python"), "-V"], capture_output=True, text=True).stdout.strip()
        if "demo" not in a.skip:
            (tmp / "demo").mkdir()
            d = _job(repo, JOBS["demo"], tmp / "demo", python=str(repo / ".venv/bin/python"), env=env)
            out.update(demo_s=d["wall_s"], demo_rc=d["rc"], demo_memory=memory(d))
            out["load_1min"].append(os.getloadavg()[0])
            print(f"fresh clone demo's job: {d['wall_s']:.1f} s" + ("" if d["rc"] == 0 else f" (failed, exit {d['rc']})"),
                  flush=True)
            out["make_demo_s"] = out["install_s"] + out["warm_s"] + d["wall_s"]
            if a.profile:
                print(profile_table("fresh clone demo's job", [d]))
        out["numba_cache_files"] = sum(1 for _ in cache.rglob("*.nbi"))
        return out
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m scenarios.bench_study", description=__doc__.split("\n\n")[0])
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--compare", type=Path, default=None, help="a second checkout to time interleaved with this one")
    p.add_argument("--skip", choices=sorted(JOBS), action="append", default=[])
    p.add_argument("--profile", action="store_true", help="where each job's wall time went (this checkout's runs)")
    p.add_argument("--fresh-clone", action="store_true",
                   help="time a fresh clone's install, compile and demo (empty NUMBA_CACHE_DIR) instead")
    a = p.parse_args(argv)
    if a.repeats < 1:
        p.error(f"--repeats must be an integer >= 1, got {a.repeats}")
    if a.compare is not None and not (a.compare / "scenarios").is_dir():
        p.error(f"--compare must be a checkout of this project (a folder with scenarios/), got {a.compare}")
    if a.fresh_clone:
        print(json.dumps({"fresh_clone": fresh_clone(a)}))
        return 0
    repos = {"this": HERE} | ({"compare": a.compare.resolve()} if a.compare else {})
    result = compare_runs(a, repos)
    if a.profile:
        for job, ds in result["this"]["jobs"].items():
            ok = [d for d in ds if d["rc"] == 0]
            print("\n" + profile_table(f"{job} ({HERE})", ok))
            print(target_line(f"{job} ({HERE})", ok))
    summary = summarise(result, list(repos))
    if a.profile:
        summary["profile"] = {job: profile([d for d in ds if d["rc"] == 0][-1]) if any(d["rc"] == 0 for d in ds) else []
                              for job, ds in result["this"]["jobs"].items()}
        summary["target"] = {job: [target(d) for d in ds if d["rc"] == 0] for job, ds in result["this"]["jobs"].items()}
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
