"""Regenerate the Listing 16 golden files: ``python tests/benchmarks/fbm3w/regen_golden.py``.

Run it only after a deliberate change of the output layout, and review the diff.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> int:
    sys.path.insert(0, str(HERE))
    from golden_case import golden_result

    from ertools.cli.output import dump_json

    result = golden_result()
    (HERE / "golden" / "score.yaml").write_text(result.to_yaml(), encoding="utf-8")
    (HERE / "golden" / "score.json").write_text(
        dump_json(result.to_dict()) + "\n", encoding="utf-8"
    )
    print(f"wrote {HERE / 'golden'}/score.yaml and score.json")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
