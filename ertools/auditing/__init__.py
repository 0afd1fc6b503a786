"""A benchmark reconstructed from its state topics: analyse the machines, rescore, compare.

Called, this package is the public API's ``ertools.audit(...)`` (:func:`ertools.api.audit`).
"""

from ertools._callable import make_callable

make_callable(__name__)
