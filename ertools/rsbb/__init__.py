"""ERL @Home 2017-19 RSBB runs: what a run's log and result file hold, and a season's files.

- :mod:`ertools.rsbb.log`: a run bag's state streams and the events derived from them
  (manual operations, goals, the end), the live scores, the referee items, the scripts' own
  tf broadcasts.
- :mod:`ertools.rsbb.results`: result files (``result_run_<n>_<date>.yaml``) and the live
  score's text forms.
- :mod:`ertools.rsbb.layout`: a season folder's files recognised by their paths, results
  paired with their bags.

What the benchmarks of 2017-19 share (each benchmark package uses them):

- :mod:`ertools.rsbb.sidefiles`: a run's side files (config, team transform, items, result
  file) given or found beside its bag; :mod:`ertools.rsbb.opened`: a run bag opened with them;
- :mod:`ertools.rsbb.tf`: ``/tf`` read once, the scripts' lookups as tf2 answered them, and
  the lookup helper's attempts;
- :mod:`ertools.rsbb.score`: the result file's ``score`` form, and a recomputed score compared
  with the live score and the result file;
- :mod:`ertools.rsbb.py2`: Python 2.7's ``round``, ``str`` and genpy's ``to_sec``.

docs/rsbb.md describes the RSBB; the data it names are in :mod:`ertools.rsbb_states`.
"""
