"""Regenerate the Listing 16 golden files: ``python tests/benchmarks/fbm3w/regen_golden.py``.

Run it only after a deliberate change of the output layout, and review the diff.
"""

from __future__ import annotations

from pathlib import Path

from ertools.cli.output import dump_json

# golden_case sits beside this script: run as a script, its folder is sys.path[0]
from tests.benchmarks.fbm3w.golden_case import golden_result

HERE = Path(__file__).resolve().parent


def main() -> int:
    result = golden_result()
    (HERE / "golden" / "score.yaml").write_text(result.to_yaml(), encoding="utf-8")
    (HERE / "golden" / "score.json").write_text(
        dump_json(result.to_dict()) + "\n", encoding="utf-8"
    )
    print(f"wrote {HERE / 'golden'}/score.yaml and score.json")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
