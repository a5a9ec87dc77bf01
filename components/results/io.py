"""The writes of a run's files: every file a run or study writes is written atomically (a reader sees the old
content or the new, never a part), through the engine's public API (:func:`mbd.atomic_write_text`,
:func:`mbd.atomic_write_bytes`, which its recorder and checkpoints use too); :func:`write_summary` writes
summary.json in its one on-disk form (indented by 2, numpy scalars and arrays as JSON numbers and lists)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from mbd import atomic_write_bytes, atomic_write_text

from .reader import SUMMARY_NAME

__all__ = ["atomic_write_bytes", "atomic_write_text", "summary_text", "write_summary"]


def _json_default(o):
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return str(o)      # what JSON has no form for (a path, an enum) is kept as its text


def summary_text(summary) -> str:
    """summary.json's text of ``summary`` (a mapping)."""
    return json.dumps(summary, indent=2, default=_json_default)


def write_summary(folder, summary) -> Path:
    """Write ``summary`` as ``folder``/summary.json, atomically; return its path."""
    path = Path(folder) / SUMMARY_NAME
    atomic_write_text(path, summary_text(summary))
    return path
