"""Helpers shared by test modules (not tests themselves): hypothesis strategies and numerical checks
(strategies), the shared DPGT runs (dpgt_runs), the element families' test scenes (contact, mesh, scenes).
A helper that more than one test module uses lives here, never in a test module."""
from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]      # the repository
DATA = ROOT / "tests" / "data"                  # committed reference data of the tests
