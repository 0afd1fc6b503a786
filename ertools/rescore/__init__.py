"""``ertools rescore``: a whole competition, from folders of logs to one results document.

The competition manifest (:mod:`~ertools.rescore.manifest`) names every benchmark's inputs and
each team's; executions (listed in the manifest, or found in the logs by
:mod:`ertools.rescore.discover`) become independent jobs (:mod:`~ertools.rescore.jobs`), scored
through the benchmark registry only, in parallel (:mod:`~ertools.rescore.parallel`), skipped
when the cache (:mod:`~ertools.rescore.cache`) already holds them, and gathered into
``results.json``/``results.csv`` (:mod:`~ertools.rescore.pipeline`), from which
:mod:`~ertools.rescore.site` renders the results page. The document's contract is
docs/rescore.md.

Called, this package is the public API's ``ertools.rescore(...)`` (:func:`ertools.api.rescore`).
"""

from ertools._callable import make_callable

make_callable(__name__)
