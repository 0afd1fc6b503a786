"""ERL @Home 2017-19 RSBB runs: what a run's log and result file hold, and a season's files.

- :mod:`ertools.rsbb.log`: a run bag's state streams and the events derived from them
  (manual operations, goals, the end), the live scores, the referee items, the scripts' own
  tf broadcasts.
- :mod:`ertools.rsbb.results`: result files (``result_run_<n>_<date>.yaml``) and the live
  score's text forms.
- :mod:`ertools.rsbb.layout`: a season folder's files recognised by their paths, results
  paired with their bags.

docs/rsbb.md describes the RSBB; the data it names are in :mod:`ertools.rsbb_states`.
"""
