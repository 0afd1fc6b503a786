"""The noise measure's rules: none. It does what the 2015 mocap_noise_statistics tool did
(distances in the plane, the tool's bins, repeated poses counted as lost) and adds what the
seed asks for (epsilon, percentiles, the suggested d_min); no deviation is printed."""

from __future__ import annotations

from ertools.fidelity import Rule

RULES: tuple[Rule, ...] = ()
