"""Peak resident memory of one run, not of the process that ran it.

A Dask worker runs several runs one after another, and the process's peak (``getrusage``'s ``ru_maxrss``) only
grows: after its third run it is the largest of the three. On Linux the kernel's high-water mark can be reset
(``/proc/self/clear_refs``, value 5), so :class:`RunPeak` resets it when a run starts and reads it (``VmHWM`` of
``/proc/self/status``) when it ends. The mark it resets is kept here, so :func:`process_peak_mb` still says the
process's own peak. Where the reset is not allowed (another OS, a locked-down /proc), the run's peak is the
process's peak so far — an upper bound — and :attr:`RunPeak.per_run` says so.
"""
from __future__ import annotations

import resource
import sys

__all__ = ["RunPeak", "process_peak_mb", "maxrss_kb"]

_STATUS, _CLEAR = "/proc/self/status", "/proc/self/clear_refs"
_earlier_kb = [0.0]       # the largest high-water mark a reset has wiped in this process [KiB]


def _hwm_kb() -> float:
    """The process's resident high-water mark since the last reset [KiB] (``ru_maxrss`` where /proc has none)."""
    try:
        with open(_STATUS) as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return float(line.split()[1])
    except OSError:
        pass
    return maxrss_kb(resource.getrusage(resource.RUSAGE_SELF))


def maxrss_kb(usage) -> float:
    """A ``resource.struct_rusage``'s (or ``os.wait4``'s) peak resident memory [KiB] (macOS reports bytes)."""
    return usage.ru_maxrss / 1024.0 if sys.platform == "darwin" else float(usage.ru_maxrss)


def process_peak_mb() -> float:
    """This process's peak resident memory [MiB], across the resets of :class:`RunPeak`."""
    return max(_earlier_kb[0], _hwm_kb()) / 1024.0


class RunPeak:
    """``peak = RunPeak()`` when a run starts (the high-water mark is reset then), ``peak.mb()`` when it ends: the
    peak resident memory [MiB] of the process meanwhile, its baseline (the interpreter, the imports) included, as the
    operating system counts it. ``per_run`` is False where the mark could not be reset (then: the process's peak so
    far, an upper bound)."""

    def __init__(self):
        before = _hwm_kb()
        try:
            with open(_CLEAR, "w") as f:
                f.write("5")
            self.per_run = True
            _earlier_kb[0] = max(_earlier_kb[0], before)
        except OSError:
            self.per_run = False

    def mb(self) -> float:
        return _hwm_kb() / 1024.0
