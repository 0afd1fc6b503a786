"""``ertools rescore``: a whole competition, from folders of logs to scored and audited results.

:mod:`ertools.rescore.discover` finds the benchmark executions in a timeline and pairs each
with its team, its GT files and its robot's own log.
"""
