"""Shared pytest configuration.

Hypothesis profiles: ``default`` (fast, used in CI and ``make test``) and ``thorough`` (many more
examples; select with HYPOTHESIS_PROFILE=thorough). No deadline: the first example of a test pays
for numpy/scipy warm-up and would trip hypothesis' timing check on a loaded 2-core machine.
"""
from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

settings.register_profile("default", max_examples=20, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", max_examples=300, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
# CI explores the same examples on every run (a green CI stays green for the same code); local runs are
# randomised so that new edge cases keep being found (as the 6e-215 rpm operating point was)
settings.register_profile("ci", max_examples=20, deadline=None, derandomize=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "default"))
