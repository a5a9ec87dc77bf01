"""A local cluster's workers leave at once when it closes (:class:`QuickExit`, registered by
:func:`scenarios.core.sweep.dask_client` on the clusters it starts itself, never on a scheduler it was given).

A worker process closes with the interpreter's finalisation of what its runs and figures imported — numba and
llvmlite, SciPy, matplotlib, h5py: 0.3–1 s a worker on a quiet machine, 2–3 s on a busy one, and the study waits
for it at its end. Nothing of a worker needs finishing by then: a sweep closes its cluster after every result was
gathered, and a run writes its results, summary and checkpoints atomically before its task returns. Dask calls a
plugin's ``teardown`` as the worker starts to close (its status "closing", before its connections and its task
thread are shut), so the worker leaves there with ``os._exit(0)``; the nanny sees a clean exit, and the worker's
directory lock stays behind in Dask's scratch folder until the next cluster's start purges it. A cluster stopped
early (Ctrl-C, a failure of the client) cuts its running tasks at once: a run resumes from its checkpoint, and a figure
being drawn then may be left unfinished until the study is run again (it redraws every figure). A teardown outside
a close — the plugin registered a second time, which removes the first — leaves the worker running.
"""
from __future__ import annotations

import os

from distributed import WorkerPlugin
from distributed.core import Status


class QuickExit(WorkerPlugin):
    """On its worker's close (Dask calls ``teardown`` as the worker stops), the process exits without the
    interpreter's finalisation."""

    name = "dpgt-quick-exit"

    def teardown(self, worker) -> None:
        if worker.status in (Status.closing, Status.closing_gracefully):
            os._exit(0)
