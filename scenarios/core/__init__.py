"""The machinery every command shares — no command lives here.

One run end to end (:mod:`.runner`), sweeps of runs on Dask (:mod:`.sweep`), many small tasks on it in batches
(:mod:`.tasks`), runs on workers that share no filesystem with the client (:mod:`.cluster`) and the skeleton every
sweep study follows (:mod:`.study`); the argument grammar (:mod:`.args`) and how every command ends (:mod:`.command`); one run
per output folder (:mod:`.lock`), a run's own peak memory (:mod:`.memory`), what a run folder holds checked before it is used (:mod:`.integrity`), requests
refused before they run (:mod:`.plausibility`); spectra and the housing sensor's signals (:mod:`.analysis`).

What belongs here: code that two or more commands (studies at the top of :mod:`scenarios`, scripts of
:mod:`scenarios.numerics`) would otherwise each write. It imports no study, no numerics script and no ``viz``
(tests/test_architecture.py holds the walls).
"""
