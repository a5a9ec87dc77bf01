"""Runnable studies (``dpgt NAME`` / ``python -m scenarios.NAME``), the run/sweep machinery, post-processing — and
the one Python entry point for scripts and notebooks (:mod:`scenarios.api`):

    import scenarios
    run = scenarios.run(condition=3, direction="reverse", set={"bearing.clearance": "30 um"}, out="results/mine")
    run.summary["outer"]["bearing_load_mean_N"], run.dataset()
"""
from __future__ import annotations

__all__ = ["run", "parameters", "Run"]


def __getattr__(name):          # lazily: `python -m scenarios.NAME` does not pay for it
    if name in __all__:
        from . import api
        return getattr(api, name)
    raise AttributeError(f"module 'scenarios' has no attribute {name!r}")
