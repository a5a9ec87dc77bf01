"""Every command the documents name keeps working as written (the numerics scripts and the
machinery live in subpackages of scenarios/): each ``python -m scenarios.NAME`` of README.md, docs/, the
Makefile and .ci/run, and each ``dpgt NAME`` of those and of ``dpgt --help``, shows its usage under its own name.

Cheaply, in this process: ``python -m`` is runpy running the module as ``__main__`` (one real subprocess shows a
shim under the interpreter's own ``-m``); ``dpgt`` is the console script's entry point called with the arguments."""
from __future__ import annotations

import contextlib
import importlib
import io
import re
import runpy
import subprocess
import sys
import tomllib
import warnings

import pytest

from tests.support import ROOT

DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), *sorted((ROOT / "docs").glob("*.ipynb")),
             ROOT / "Makefile", ROOT / ".ci" / "run"]
PYTHON_M = re.compile(r"-m\s+scenarios\.([a-z_]+)\b")           # "python -m", "$(PY) -m", across a line break
DPGT = re.compile(r"(?<![\w./-])dpgt ([a-z_]+)\b")               # not "components.dpgt import"
# runs no parser: it compiles the engine's kernels (a minute on a fresh machine) — resolved, not run
NO_HELP = {"warm"}


def _documented(pattern: re.Pattern) -> set[str]:
    return {m.group(1) for doc in DOCUMENTS for m in pattern.finditer(doc.read_text(encoding="utf-8"))}


def _dpgt():
    """The console script's function, as pyproject.toml declares it."""
    target = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["scripts"]["dpgt"]
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


PYTHON_M_NAMES = sorted(_documented(PYTHON_M))


def _dpgt_names() -> list[str]:
    from scenarios.cli import available

    return sorted(_documented(DPGT) | set(available()))


def test_the_documents_name_the_commands_they_are_known_to_name():
    """The patterns find what is written (else the tests below would check nothing)."""
    assert {"paper_study", "spectrum", "benchmark", "bench_engine", "bench_statistics", "warm", "params",
            "work_precision", "stability"} <= set(PYTHON_M_NAMES)
    assert {"params", "animate", "modal", "bearing_rig", "tolerance_study"} <= _documented(DPGT)
    assert PYTHON_M.findall("make: $(PY) -m scenarios.warm\npython -m\nscenarios.benchmark") == ["warm", "benchmark"]
    assert DPGT.findall("from components.dpgt import build_dpgt; `dpgt params --grep x`") == ["params"]


def _run(fn) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = fn()
        except SystemExit as exc:
            code = exc.code
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("name", PYTHON_M_NAMES)
def test_every_documented_python_m_command_resolves_and_shows_its_usage(name, monkeypatch):
    module = f"scenarios.{name}"
    assert importlib.util.find_spec(module) is not None, f"python -m {module}: no such module"
    if name in NO_HELP:
        assert callable(importlib.import_module(module).main)
        return
    monkeypatch.setattr(sys, "argv", [module, "--help"])
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "'scenarios.* found in sys.modules", RuntimeWarning)  # imported by a test
        code, out, err = _run(lambda: runpy.run_module(module, run_name="__main__", alter_sys=True))
    assert code in (0, None) and out.startswith(f"usage: python -m {module} "), (code, out[:200], err[-500:])


@pytest.mark.parametrize("name", _dpgt_names())
def test_every_documented_dpgt_command_resolves_and_shows_its_usage(name):
    code, out, err = _run(lambda: _dpgt()([name, "--help"]))
    assert code == 0 and out.startswith(f"usage: dpgt {name} "), (code, out[:200], err[-500:])


def test_the_dpgt_listing_names_every_command_it_runs():
    from scenarios.cli import SCENARIOS

    code, out, _ = _run(lambda: _dpgt()([]))
    listed = re.findall(r"^  (\w+) ", out, flags=re.M)
    assert code == 0 and listed == list(SCENARIOS)


def test_a_moved_script_runs_under_the_interpreters_own_python_m():
    """The shim of a numerics script as the interpreter runs it (its own sys.path and __main__)."""
    r = subprocess.run([sys.executable, "-m", "scenarios.bench_static", "--help"], cwd=ROOT, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0 and r.stdout.startswith("usage: python -m scenarios.bench_static "), r.stderr[-500:]
