"""The numerics and benchmark scripts: how well and how fast the engine integrates, not what the machine does.

Error against run time for every integrator (:mod:`.work_precision`), stiff and extreme cases (:mod:`.stability`),
the speed target of the full DPGT (:mod:`.benchmark`), what single parts cost (``bench_*``: the engine on networks of
stiff bodies, the compiled mesh kernel, the statistics observer, a static solution, a study end to end, Dask's
scheduling of many small tasks, what threads buy one run), and the one-off compile of the engine's kernels (:mod:`.warm`); :mod:`.common`
holds what the first three share (the test
problems, the settled state, the contender runs, the error metrics).

Each script runs as its documented command, ``python -m scenarios.NAME`` (a shim of that name at the top of
:mod:`scenarios` imports the script's ``main``; the code is here) or ``dpgt NAME``. What belongs here: a script
whose answer is about the numerics or the cost of the code. A script imports :mod:`scenarios.core` and
:mod:`.common`, never a study (tests/test_architecture.py holds the walls); their results are in docs/numerics.md.
"""
