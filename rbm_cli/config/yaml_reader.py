"""A strict YAML reader for configs: YAML 1.2 numbers, no duplicate keys, bounded aliases.

:func:`read_yaml` raises ConfigError ``cannot parse <source>: <problem> (line N, ...)``
for every problem, one line. No file I/O here: :mod:`rbm_cli.config.load` reads the file.
"""

from __future__ import annotations

import re
from typing import Any

import yaml

from rbm_cli.base.errors import ConfigError
from rbm_cli.config.validate import join, one_line


class _Loader(yaml.SafeLoader):
    """SafeLoader whose floats follow YAML 1.2: ``5e9`` and ``1e-3`` are numbers.

    YAML 1.1 (PyYAML's default) needs a dot in a float, so ``5e9`` is a string there.
    """


_FLOAT_TAG = "tag:yaml.org,2002:float"
_FLOAT_RE = re.compile(
    r"""^(?:
        [-+]?[0-9][0-9_]*\.[0-9_]*(?:[eE][-+]?[0-9]+)?
      | [-+]?[0-9][0-9_]*[eE][-+]?[0-9]+
      | [-+]?\.[0-9][0-9_]*(?:[eE][-+]?[0-9]+)?
      | [-+]?\.(?:inf|Inf|INF)
      | \.(?:nan|NaN|NAN)
    )$""",
    re.VERBOSE,
)
_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != _FLOAT_TAG]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(_FLOAT_TAG, _FLOAT_RE, list("-+0123456789."))
# integers as YAML 1.2 reads them: decimal only. YAML 1.1's base 60 (``1:30`` = 90), octal
# (``012`` = 10), binary and hex forms stay strings, which the checkers refuse by name.
_INT_TAG = "tag:yaml.org,2002:int"
_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != _INT_TAG]
    for first, resolvers in _Loader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(
    _INT_TAG, re.compile(r"^[-+]?(?:0|[1-9][0-9_]*)$"), list("-+0123456789")
)
#: Largest expansion of a document's aliases and merge keys: its node count, aliases
#: followed, may be at most this multiple of its distinct nodes (plus EXPANSION_SLACK).
EXPANSION_FACTOR = 4
EXPANSION_SLACK = 1000


def _yaml_problem(exc: yaml.YAMLError, text: str = "") -> str:
    """``<what is wrong> (line N, column M)`` from a PyYAML error."""
    if isinstance(exc, yaml.reader.ReaderError):
        code = exc.character if isinstance(exc.character, int) else ord(exc.character)
        before = text[: exc.position]
        line, column = before.count("\n") + 1, exc.position - before.rfind("\n")
        return f"a control character (U+{code:04X}) at line {line}, column {column}: delete it"
    if not isinstance(exc, yaml.MarkedYAMLError):
        return one_line(str(exc))
    what = ", ".join(p for p in (exc.context, exc.problem) if p) or "invalid YAML"
    mark = exc.problem_mark or exc.context_mark
    where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
    return one_line(what) + where


def _duplicate_key(root: yaml.Node) -> tuple[str, int] | None:
    """Key path and line of the first key repeated within one mapping, if any."""
    stack: list[tuple[yaml.Node, str]] = [(root, "")]
    seen: set[int] = set()
    while stack:
        node, path = stack.pop()
        if id(node) in seen:  # aliases share nodes
            continue
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            keys: set[str] = set()
            for key_node, value_node in node.value:
                if not isinstance(key_node, yaml.ScalarNode) or key_node.tag.endswith(":merge"):
                    stack.append((value_node, path))
                    continue
                key_path = join(path, key_node.value)
                if key_node.value in keys:
                    return key_path, key_node.start_mark.line + 1
                keys.add(key_node.value)
                stack.append((value_node, key_path))
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((item, join(path, i)) for i, item in enumerate(node.value))
    return None


def _expanded_size(root: yaml.Node, limit: int) -> int:
    """Nodes of the document with every alias and merge key followed, counted up to
    ``limit`` (linear in the distinct nodes: shared nodes are counted once and their
    size reused). Raises ConfigError for a recursive alias."""
    size: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            on_path.discard(key)
            children = _children(node)
            size[key] = min(limit + 1, 1 + sum(size[id(c)] for c in children))
            continue
        if key in size:
            continue
        if key in on_path:
            mark = node.start_mark
            raise ConfigError(f"a recursive alias (line {mark.line + 1}): a value contains itself")
        on_path.add(key)
        stack.append((node, True))
        for child in _children(node):
            if id(child) in on_path:
                mark = child.start_mark
                raise ConfigError(
                    f"a recursive alias (line {mark.line + 1}): a value contains itself"
                )
            if id(child) not in size:
                stack.append((child, False))
    return size[id(root)]


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _distinct_nodes(root: yaml.Node) -> int:
    seen: set[int] = set()
    stack = [root]
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        stack.extend(_children(node))
    return len(seen)


def read_yaml(text: str, source: str) -> Any:
    """Parse YAML text (YAML 1.2 numbers, no duplicate keys); None for an empty document.

    Aliases and merge keys may not expand the document beyond EXPANSION_FACTOR times its
    distinct nodes (a "billion laughs" document is refused before it is built), so no
    construct costs more than a small multiple of its size.

    Every problem raises ConfigError ``cannot parse <source>: <problem> (line N, ...)``.
    """
    loader = None
    try:
        loader = _Loader(text)  # the reader refuses control characters here
        node = loader.get_single_node()
        if node is None:
            return None
        limit = EXPANSION_FACTOR * _distinct_nodes(node) + EXPANSION_SLACK
        if _expanded_size(node, limit) > limit:
            raise ConfigError(
                f"cannot parse {source}: its aliases and merge keys (*, <<) expand it to more"
                f" than {limit} values, {EXPANSION_FACTOR}x its size: write the values out"
            )
        duplicate = _duplicate_key(node)
        if duplicate is not None:
            raise ConfigError(
                f"cannot parse {source}: duplicate key {duplicate[0]!r} (line {duplicate[1]});"
                " each key may appear once"
            )
        return loader.construct_document(node)
    except yaml.YAMLError as exc:
        raise ConfigError(f"cannot parse {source}: {_yaml_problem(exc, text)}") from None
    except ConfigError as exc:
        message = str(exc)
        if not message.startswith("cannot parse"):
            message = f"cannot parse {source}: {message}"
        raise ConfigError(message) from None
    except RecursionError:
        raise ConfigError(f"cannot parse {source}: nested too deeply") from None
    except (ValueError, TypeError, OverflowError) as exc:  # e.g. a 5000-digit integer
        raise ConfigError(f"cannot parse {source}: {one_line(str(exc).split(';')[0])}") from None
    finally:
        if loader is not None:
            loader.dispose()
