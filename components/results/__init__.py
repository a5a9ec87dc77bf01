"""The results of a run, in one module.

* :mod:`.summary` — :class:`Summary`: summary.json typed (per-bearing-kind and per-mesh sections, the failed-run
  form, the words and units of its keys, :data:`SUMMARY_WORDS`).
* :mod:`.reader` — :func:`open_run`, :func:`read_results`, :func:`open_dataset`, :func:`load_summary`,
  :func:`count_samples`: the one reader of results.nc and summary.json, which viz and every study read through.
* :mod:`.io` — the atomic writes and summary.json's writer (imported as ``components.results.io``: it takes the
  engine's public API, which the reader does not need).
* :mod:`.schema` — what results.nc holds: the element outputs the runner records, their units and instance
  coordinates, the drawing geometry (imported as ``components.results.schema``: it needs the scene and the engine).

This namespace and the reader import nothing of the project beyond the summary: viz, which must not import the
engine, enters here.
"""
from .reader import (RESULTS_NAME, SUMMARY_NAME, DamagedResults, Results, ResultsError, RunFiles, count_samples,
                     json_attr, load_summary, open_dataset, open_run, read_results, results_path)
from .summary import (BEARING_KINDS, DIMENSIONLESS_KEYS, SUMMARY_WORDS, UNIT_SUFFIXES, Quantity, Section, Summary,
                      describe_key, format_change, percent_change, unit_of_key)

__all__ = ["RESULTS_NAME", "SUMMARY_NAME", "DamagedResults", "Results", "ResultsError", "RunFiles", "count_samples",
           "json_attr", "load_summary", "open_dataset", "open_run", "read_results", "results_path", "BEARING_KINDS", "DIMENSIONLESS_KEYS",
           "SUMMARY_WORDS", "UNIT_SUFFIXES", "Quantity", "Section", "Summary", "describe_key", "format_change",
           "percent_change", "unit_of_key"]
