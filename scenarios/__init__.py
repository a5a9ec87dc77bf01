"""The commands of the project, in three kinds:

* the studies a user runs — ``dpgt NAME`` / ``python -m scenarios.NAME`` for each module here (paper_study, demo,
  lubricant_study, fault_study, gear_quality, tolerance_study, spectrum, bearing_rig, modal, params) — with the two
  entrances: the console command (:mod:`scenarios.cli`) and the Python entry point for scripts and notebooks
  (:mod:`scenarios.api`);
* :mod:`scenarios.numerics`: the numerics and benchmark scripts (their ``python -m scenarios.NAME`` are shims here);
* :mod:`scenarios.core`: the machinery they share (one run, sweeps, the study skeleton, arguments, how commands end,
  locks, run-folder integrity, plausibility, spectra).

    import scenarios
    run = scenarios.run(condition=3, direction="reverse", set={"bearing.clearance": "30 um"}, out="results/mine")
    run.summary["outer"]["bearing_load_mean_N"], run.dataset()
"""
from __future__ import annotations

__all__ = ["run", "parameters", "Run"]


def __getattr__(name):
    if name in __all__:
        from . import api  # deferred: the runner (≈ 1 s) only for scenarios.run; every command imports this package
        return getattr(api, name)
    raise AttributeError(f"module 'scenarios' has no attribute {name!r}")
