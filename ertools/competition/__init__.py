"""``ertools rescore``: a whole competition, from folders of logs to one results document.

The competition manifest (:mod:`~ertools.competition.manifest`) names every benchmark's inputs
and each team's; executions (listed in the manifest, or found in the logs by
:mod:`ertools.competition.discover`) become independent jobs
(:mod:`~ertools.competition.jobs`), scored through the benchmark registry only, in parallel
(:mod:`~ertools.competition.parallel`), skipped when the cache
(:mod:`~ertools.competition.cache`) already holds them, and gathered into
``results.json``/``results.csv`` (:mod:`~ertools.competition.pipeline`), from which
:mod:`~ertools.competition.site` renders the results page. The document's contract is
docs/rescore.md. The public API's function is ``ertools.rescore``.
"""
