"""What a run folder holds is checked before it is used (README "What a user can expect").

* A damaged file — a checkpoint or recorder chunk that does not load, a ``summary.json`` that is not a JSON
  object, a ``results.nc`` that does not open or holds fewer samples than its summary says — is named in a
  warning, moved aside (renamed ``NAME.damaged-YYYYmmdd-HHMMSS``, never deleted) and recomputed.
* Finished results are never replaced silently by a run of other parameters: a folder whose ``summary.json``
  was made from other parameters or settings is refused (:class:`OtherResults`, a usage error) unless the
  user passes ``--overwrite``. The same parameters made by other code are recomputed (and said so).
"""
from __future__ import annotations

import hashlib
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from components.results import DamagedResults, Summary, count_samples, load_summary
from mbd.simulate import load_state

__all__ = ["OtherResults", "move_aside", "read_summary", "results_intact", "checkpoint_usable", "claim_folder", "differences",
           "DAMAGED"]

DAMAGED = ".damaged-"


class OtherResults(Exception):
    """The folder holds finished results of other parameters (the message names them and the way out)."""


def warn(msg: str) -> None:
    print(f"warning: {msg}", file=sys.stderr, flush=True)


def move_aside(path, why: str, into=None) -> Path:
    """Rename a damaged ``path`` to NAME.damaged-STAMP (in ``into`` or beside it), say so, return the new path."""
    path = Path(path)
    stamp = time.strftime("%Y%m%d-%H%M%S")
    dest = Path(into or path.parent) / f"{path.name}{DAMAGED}{stamp}"
    n = 1
    while dest.exists():
        dest = dest.with_name(f"{path.name}{DAMAGED}{stamp}-{n}")
        n += 1
    os.replace(path, dest)
    warn(f"{path} is damaged ({why}); moved aside to {dest.name}, recomputing")
    return dest


def read_summary(path) -> Summary | None:
    """The summary at ``path``; None when absent or damaged (a damaged one is moved aside)."""
    try:
        return load_summary(path)
    except DamagedResults as exc:
        move_aside(exc.path, exc.why)
        return None


def results_intact(path, samples: int | None = None) -> bool:
    """Whether the results file opens and holds ``samples`` time samples; a damaged one is moved aside."""
    path = Path(path)
    if not path.exists():
        return False
    try:
        n = count_samples(path)
    except DamagedResults as exc:
        move_aside(path, exc.why)
        return False
    if samples is not None and n != samples:
        move_aside(path, f"{n} time samples where its summary says {samples}")
        return False
    return True


def _npz_loads(path) -> bool:
    try:
        with np.load(path) as d:
            for k in d.files:
                d[k]
        return True
    except Exception:               # zipfile.BadZipFile, EOFError, ValueError, OSError ...
        return False


def checkpoint_usable(ckpt, parts) -> bool:
    """Whether the checkpoint and the recorder chunks it relies on load. A damaged checkpoint is moved
    aside; a damaged chunk too, and with it the checkpoint (it cannot resume without the chunk's samples)."""
    ckpt, parts = Path(ckpt), Path(parts)
    if not ckpt.exists():
        return False
    try:
        _, extra = load_state(ckpt)
        n_chunks = int(extra.get("recorder", {}).get("n_chunks", 0))
    except Exception as exc:
        move_aside(ckpt, f"does not load: {type(exc).__name__}")
        return False
    for i in range(n_chunks):
        chunk = parts / f"chunk_{i:06d}.npz"
        if not chunk.exists() or not _npz_loads(chunk):
            if chunk.exists():
                move_aside(chunk, "recorder chunk does not load", into=ckpt.parent)
            move_aside(ckpt, f"its recorded samples ({chunk.name}) are {'damaged' if chunk.exists() else 'missing'}")
            return False
    return True


def claim_folder(folder, parameters_fp: str, full_fp: str | None, overwrite: bool, what: str = "",
                 description: dict | None = None) -> str:
    """Check that ``folder`` may take a run of these parameters: "new" (nothing finished there), "same"
    (finished from the same parameters and code), "recompute" (same parameters, other code) or "overwrite"
    (other parameters, ``overwrite`` given). Other parameters without ``overwrite``: :class:`OtherResults`,
    naming what differs (``description``: the run's :func:`scenarios.core.runner.run_description`, against the one
    the finished summary keeps)."""
    s = read_summary(Path(folder) / "summary.json")
    if s is None:
        return "new"
    if full_fp is not None and s.get("fingerprint") == full_fp:
        return "same"
    if s.get("parameters_fingerprint") == parameters_fp:
        return "recompute"
    if overwrite:
        return "overwrite"
    raise OtherResults(f"{folder} holds finished results of other parameters or settings{what}"
                       f"{differences(s.get('run_description'), description)}; pass --overwrite to replace them, "
                       f"or choose another --out")


def differences(old: dict | None, new: dict | None, most: int = 4) -> str:
    """' (key: old → new, ...)' for the first ``most`` keys whose values differ, '' when unknown."""
    if not old or not new:
        return ""
    keys = [k for k in sorted(set(old) | set(new)) if old.get(k) != new.get(k)]
    if not keys:
        return ""
    shown = ", ".join(f"{k}: {old.get(k, '(none)')} → {new.get(k, '(none)')}" for k in keys[:most])
    return f" ({shown}{f' and {len(keys) - most} more' if len(keys) > most else ''})"


def claim_for_inputs(folder, inputs: dict, overwrite: bool) -> dict:
    """For a command whose run is one short computation (the bearing rig, the modal analysis): ``folder`` may take it
    when it holds nothing, or a summary of the same ``inputs`` (the command's options and the text of its files);
    a summary of other inputs is refused (:class:`OtherResults`, naming what differs) unless ``overwrite``. Returns
    the keys its summary.json keeps so that the next run can tell (``parameters_fingerprint``, ``run_description``)."""
    described = {k: str(v) for k, v in sorted(inputs.items())}
    fp = hashlib.sha256(json.dumps(described, sort_keys=True).encode()).hexdigest()[:16]
    claim_folder(folder, fp, None, overwrite, description=described)
    return {"parameters_fingerprint": fp, "run_description": described}


def command_inputs(a, files: tuple[str, ...] = ("params",)) -> dict:
    """A command's parsed options as its inputs, without those that do not change its results (--out, --overwrite,
    --no-progress, --threads); the option ``files`` by their text, so that an edited file is other inputs."""
    skip = {"out", "overwrite", "no_progress", "threads"}
    d = {k: v for k, v in vars(a).items() if k not in skip}
    for k in files:
        if d.get(k):
            d[k] = f"{d[k]}: {Path(d[k]).read_text(encoding='utf-8', errors='replace')}"
    return d
