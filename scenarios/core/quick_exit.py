"""A local cluster's workers leave at once when it closes (:class:`QuickExit`, registered by
:func:`scenarios.core.sweep.dask_client` on the clusters it starts itself, never on a scheduler it was given).

A worker process closes with the interpreter's finalisation of what its runs and figures imported — numba and
llvmlite, SciPy, matplotlib, h5py: 0.3–1 s a worker on a quiet machine, 2–3 s on a busy one, and the study waits
for it at its end. Nothing of a worker needs finishing by then: a cluster closes after every result was gathered,
and each run and figure writes its files whole (atomically) before its task returns; a cluster stopped early
(Ctrl-C, a failure of the client) leaves what a killed worker leaves, which a run's resume handles. So the worker's
last act, after Dask's own close of its connections and plugins, is ``os._exit(0)``; the nanny sees a clean exit.
"""
from __future__ import annotations

import os

from distributed import WorkerPlugin


class QuickExit(WorkerPlugin):
    """On its worker's close (Dask calls ``teardown`` as the worker stops), the process exits without the
    interpreter's finalisation."""

    name = "dpgt-quick-exit"

    def teardown(self, worker) -> None:
        os._exit(0)
