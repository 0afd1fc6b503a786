"""Item lists (seed Listing 9) and vanilla lists."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from ertools.configs.items import Item, ItemSpread, items_to_yaml, load_items, parse_items
from ertools.errors import ConfigError

# The Listing 9 layout (rosparam dump: keys alphabetical, numbers as flow lists), rounded
# quaternions as people type them.
LISTING_9 = """
items:
- class: a
  id: 1
  instance: a1
  rot: [-0.00512, 0.00311, -0.00402, 0.99997]
  trans: [0.02120, -0.24310, -0.01105]
- class: a
  id: 2
  instance: a2
  rot: [0.00204, -0.00150, 0.38268, 0.92388]
  trans: [0.01733, -0.26012, -0.01321]
"""


def test_listing_9(tmp_path: Path) -> None:
    path = tmp_path / "fbm1h.yaml"
    path.write_text(LISTING_9, encoding="utf-8")
    items = load_items(path)
    assert len(items) == 2 and not items.is_vanilla
    a1 = items.by_id(1)
    assert a1 is not None and (a1.item_class, a1.instance) == ("a", "a1")
    assert a1.trans == (0.02120, -0.24310, -0.01105)
    # The quaternion is rounded to 5 decimals: normalised on load (norm 1 + ~1e-5).
    assert a1.rot is not None and math.isclose(sum(c * c for c in a1.rot), 1.0)
    assert a1.rot[3] == pytest.approx(0.99997, abs=2e-5)
    assert items.by_instance(" a2 ") is items.by_id(2)


def test_vanilla_list_2015_placeholders() -> None:
    data = yaml.safe_load(
        "items:\n- {class: trays, id: 1, instance: black_tray, rot: [0, 0, 0, 1], trans: [0, 0, 0]}"
        "\n- {class: others, id: 2, instance: '7'}\n"
    )
    items = parse_items(data, "v.yaml", require_transforms=False)
    assert items.is_vanilla and items.items[1].instance == "7"
    with pytest.raises(ConfigError, match="item 2: missing 'trans'"):
        parse_items(data, "v.yaml")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{}", "missing key 'items'"),
        ("items: []", "non-empty list"),
        ("items:\n- {id: 1, class: a}", "missing key 'instance'"),
        ("items:\n- {id: x, class: a, instance: a}", "id must be an integer"),
        (
            "items:\n- {id: 1, class: a, instance: a, trans: [0, 0, 0], rot: [0, 0, 0, 1]}\n"
            "- {id: 1, class: b, instance: b}",
            "duplicate id 1",
        ),
        ("items:\n- {id: 1, class: a, instance: a, trans: [0, 0], rot: [0,0,0,1]}", "3 numbers"),
        ("items:\n- {id: 1, class: a, instance: a, trans: [0,0,0], rot: [0,0,0,0]}", "zero"),
        ("items:\n- {id: 1, class: a, instance: a, trans: [0,.nan,0], rot: [0,0,0,1]}", "finite"),
    ],
)
def test_bad_lists(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError, match=message) as info:
        load_items(path)
    assert str(path) in str(info.value)


def test_write_and_read_back(tmp_path: Path) -> None:
    spread = ItemSpread(0.0003, 0.02, 240, 12.5, 14.5)
    items = [
        Item(1, "Bearing Boxes ", "AX-16", (0.01, -0.2, 0.003), (0.0, 0.0, 0.6, 0.8), spread),
        Item(2, "b", "b1"),
    ]
    text = items_to_yaml(items)
    # Listing 9 layout: keys alphabetical, numbers as flow lists.
    assert "  rot: [0.0, 0.0, 0.6, 0.8]\n" in text and text.startswith("items:\n- class:")
    path = tmp_path / "out.yaml"
    path.write_text(text, encoding="utf-8")
    back = load_items(path, require_transforms=False)
    assert back.items[0] == items[0]
    # An item without transform is written with the 2015 placeholders.
    assert back.items[1].trans == (0.0, 0.0, 0.0) and back.items[1].rot == (0.0, 0.0, 0.0, 1.0)


@pytest.mark.parametrize("name", ["fbm1h", "fbm1w"])
def test_shipped_lists_are_vanilla_listing_9(name: str) -> None:
    path = Path(__file__).resolve().parents[3] / "configs" / f"{name}.yaml"
    items = load_items(path)  # identity placeholders count as transforms: loads for scoring
    assert items.is_vanilla
    ids = [i.id for i in items.items]
    assert ids == list(range(1, len(ids) + 1))
