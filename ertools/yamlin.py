"""Reading YAML: PyYAML's safe loader with the limits every file and payload ertools reads needs.

One loader for every YAML text ertools parses (configs, manifests, rosbag2 ``metadata.yaml``,
state payloads), so that its limits are set once:

- nesting: no deeper than :data:`MAX_DEPTH`, counted in the data the text builds, aliases
  included (an alias of a 60-deep list, placed 60 deep, builds 120 levels), whatever the text
  says (tags, comments); an alias of the node that contains it (a list holding itself) is
  refused: the data would be endless;
- duplicate keys: refused with the line of both (PyYAML keeps the last silently: a second
  ``waypoints:`` block replaced the first), or, for payloads written by the 2015 nodes and the
  robots, collected so that the caller can read them as PyYAML (and the 2015 nodes) did and
  say so (:func:`load`'s ``duplicates``);
- tags: the safe ones only; ``tuples`` also reads ``!!python/tuple`` as a list (the ERL RSBB
  acquirer's transform files), ``plain`` reads any ``!!python/...`` or ``!`` tag as the plain
  data under it (the 2015 nodes' ``yaml.dump`` of a ``Pose2D``). Nothing is ever constructed
  but mappings, lists, strings and numbers; nothing is executed.
"""

from __future__ import annotations

from typing import Any, Literal

import yaml
from yaml import YAMLError
from yaml.composer import ComposerError
from yaml.constructor import ConstructorError
from yaml.events import AliasEvent
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from ertools.frozen_dataclass import frozen_dataclass

__all__ = ["MAX_DEPTH", "DuplicateKey", "DuplicateKeyError", "SafeLoader", "YAMLError", "load"]

MAX_DEPTH = 64
Tags = Literal["safe", "tuples", "plain"]
_MERGE = "tag:yaml.org,2002:merge"


@frozen_dataclass
class DuplicateKey:
    """A key given twice in one mapping: the key as shown, and the lines (1-based) of both."""

    key: str
    line: int
    first_line: int

    def text(self) -> str:
        return f"duplicate key {self.key} at line {self.line} (first at line {self.first_line})"


class DuplicateKeyError(ConstructorError):
    """A mapping gives a key twice (refused: which value was meant cannot be known)."""


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


class SafeLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` with :data:`MAX_DEPTH` and duplicate keys refused (or collected)."""

    def __init__(self, stream: str, duplicates: list[DuplicateKey] | None = None) -> None:
        super().__init__(stream)
        self.depth = 0
        self.heights: dict[int, int] = {}  # id(node) -> levels of data it builds
        self.duplicates = duplicates

    def compose_node(self, parent: Node | None, index: int) -> Node | None:
        if self.check_event(AliasEvent):
            event = self.peek_event()  # type: ignore[no-untyped-call]
            node = self.anchors.get(event.anchor)
            if node is not None:  # an undefined alias is PyYAML's own error
                height = self.heights.get(id(node))
                if height is None:
                    raise ComposerError(
                        None, None, f"alias *{event.anchor} refers to itself", event.start_mark
                    )
                if self.depth + height > MAX_DEPTH:
                    self._too_deep(event.start_mark)
            return super().compose_node(parent, index)
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                self._too_deep(self.peek_event().start_mark)  # type: ignore[no-untyped-call]
            node = super().compose_node(parent, index)
        finally:
            self.depth -= 1
        if node is not None:
            self.heights[id(node)] = 1 + _child_height(node, self.heights)
        return node

    @staticmethod
    def _too_deep(mark: Any) -> None:
        raise ComposerError(None, None, f"nested more than {MAX_DEPTH} levels deep", mark)

    def construct_mapping(self, node: MappingNode, deep: bool = False) -> dict[Any, Any]:
        if isinstance(node, MappingNode):
            self._check_keys(node)
        return super().construct_mapping(node, deep)

    def _check_keys(self, node: MappingNode) -> None:
        first: dict[Any, Node] = {}
        for key_node, value_node in node.value:
            if key_node.tag == _MERGE:
                # merged keys may be overridden (what a merge is for); each merged mapping
                # is checked itself, even one written inline and built nowhere else
                merged = value_node.value if isinstance(value_node, SequenceNode) else [value_node]
                for m in merged:
                    if isinstance(m, MappingNode):
                        self._check_keys(m)
                continue
            key = self.construct_object(key_node, deep=True)
            try:
                seen = first.setdefault(key, key_node)
            except TypeError:
                continue  # an unhashable key: PyYAML's own error follows
            if seen is key_node:
                continue
            found = DuplicateKey(
                _short(key),
                key_node.start_mark.line + 1,
                seen.start_mark.line + 1,
            )
            if self.duplicates is None:
                raise DuplicateKeyError(
                    None,
                    None,
                    f"duplicate key {found.key} (first at line {found.first_line}): which "
                    "value is meant cannot be known; remove one",
                    key_node.start_mark,
                )
            self.duplicates.append(found)


def _child_height(node: Node, heights: dict[int, int]) -> int:
    if isinstance(node, ScalarNode):
        return 0
    if isinstance(node, SequenceNode):
        children = node.value
    else:
        children = [n for pair in node.value for n in pair]
    return max((heights.get(id(c), 1) for c in children), default=0)


class TupleLoader(SafeLoader):
    """:class:`SafeLoader` that also reads ``!!python/tuple`` as a list."""


class PlainTagsLoader(SafeLoader):
    """:class:`SafeLoader` that reads python-specific and local tags as the plain data under
    them (nothing constructed)."""


def _tuple_as_list(loader: SafeLoader, node: Node) -> list[Any]:
    if not isinstance(node, SequenceNode):
        raise ConstructorError(None, None, "!!python/tuple must tag a sequence", node.start_mark)
    return list(loader.construct_sequence(node, deep=True))


def _construct_plain(loader: SafeLoader, suffix: str, node: Node) -> Any:
    if isinstance(node, MappingNode):
        return loader.construct_mapping(node, deep=True)
    if isinstance(node, SequenceNode):
        return loader.construct_sequence(node, deep=True)
    return loader.construct_scalar(node)  # type: ignore[arg-type]


TupleLoader.add_constructor("tag:yaml.org,2002:python/tuple", _tuple_as_list)
PlainTagsLoader.add_multi_constructor("tag:yaml.org,2002:python/", _construct_plain)
PlainTagsLoader.add_multi_constructor("!", _construct_plain)

_LOADERS: dict[str, type[SafeLoader]] = {
    "safe": SafeLoader,
    "tuples": TupleLoader,
    "plain": PlainTagsLoader,
}


def load(text: str, *, tags: Tags = "safe", duplicates: list[DuplicateKey] | None = None) -> Any:
    """The data of one YAML document, read safely within the limits above.

    Args:
        text: the YAML text.
        tags: ``safe`` (PyYAML's safe tags), ``tuples`` or ``plain`` (see the module).
        duplicates: None: a key given twice in a mapping raises :class:`DuplicateKeyError`;
            a list: each duplicate is appended to it and the last value is kept (PyYAML's
            reading, which the 2015 nodes used).

    Raises:
        yaml.YAMLError: malformed text, a limit exceeded, a duplicate key. Python's own
            ``RecursionError`` cannot arise from the text within :data:`MAX_DEPTH`.
    """
    loader = _LOADERS[tags](text, duplicates)
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()
