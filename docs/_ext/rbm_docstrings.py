"""How the site reads the project's docstrings (autodoc, then napoleon's numpydoc).

The docstrings are written for ``help()`` and a terminal first; three of their habits are
not what napoleon and reStructuredText expect, and each cost a name its docstring on the
Python reference page (or the build a warning). Before napoleon reads a docstring:

- :func:`titled_fields`: a class whose attributes are listed as fields right after its
  summary, without an ``Attributes`` title (``rbm.DomainComparison``), gets the title;
- :func:`split_field_lines`: a field on one line, ``name : type  text`` (two spaces before
  the description), becomes napoleon's two lines (the description indented below);
- :func:`escape_bars`: ``|x|`` (an absolute value, ``|T/N|``) is text, not a
  reStructuredText substitution: each ``|`` outside a ``literal`` is escaped.
"""

from __future__ import annotations

import re

#: numpydoc sections whose lines are fields.
FIELD_SECTIONS = {"Parameters", "Returns", "Yields", "Raises", "Other Parameters", "Attributes"}
#: A field on one line: ``name : type`` then two spaces or more, then its description.
FIELD = re.compile(r"^(?P<head>\S(?:.*?\S)?)\s{2,}(?P<text>\S.*)$")
#: A field's head: ``name : type`` (names separated by commas).
HEAD = re.compile(r"^[\w*]+(?:, [\w*]+)* : \S")


def _is_title(lines: list[str], k: int) -> bool:
    nxt = lines[k + 1] if k + 1 < len(lines) else ""
    return bool(lines[k].strip()) and bool(nxt.strip()) and set(nxt.strip()) == {"-"}


def titled_fields(lines: list[str], what: str) -> list[str]:
    """A class docstring's fields that follow its summary under no title, titled
    ``Attributes`` (the fields run to the next blank line followed by a title or text)."""
    if what not in ("class", "exception"):
        return lines
    for k, line in enumerate(lines):
        if _is_title(lines, k):
            return lines  # a titled section comes first: nothing untitled to find
        previous = lines[k - 1] if k else ""
        if k and not previous.strip() and HEAD.match(line) and FIELD.match(line):
            return [*lines[:k], "Attributes", "----------", *lines[k:]]
    return lines


def split_field_lines(lines: list[str]) -> list[str]:
    """Split ``name : type  text`` into ``name : type`` and the indented ``text`` in the
    field sections (:data:`FIELD_SECTIONS`)."""
    out: list[str] = []
    in_fields = False
    for k, line in enumerate(lines):
        if _is_title(lines, k):
            in_fields = line.strip() in FIELD_SECTIONS
            out.append(line)
            continue
        if in_fields and line.strip() and not line.startswith(" ") and set(line.strip()) != {"-"}:
            match = FIELD.match(line)
            if match:
                out += [match["head"], "    " + match["text"]]
                continue
        out.append(line)
    return out


def escape_bars(lines: list[str]) -> list[str]:
    """Each ``|`` outside an inline literal (double backquotes) escaped: ``|T/N|`` is an
    absolute value, not a substitution reference."""
    out = []
    for line in lines:
        parts = line.split("``")
        for k in range(0, len(parts), 2):  # the even parts are outside literals
            parts[k] = re.sub(r"(?<!\\)\|", r"\\|", parts[k])
        out.append("``".join(parts))
    return out


def read_docstring(lines: list[str], what: str) -> list[str]:
    """The three steps of the module, in order."""
    return escape_bars(split_field_lines(titled_fields(lines, what)))


def _process(app, what, name, obj, options, lines) -> None:
    lines[:] = read_docstring(list(lines), what)


def setup(app):  # pragma: no cover - exercised by the docs build
    app.setup_extension("sphinx.ext.autodoc")
    # before napoleon (priority 500), which reads the fields as numpydoc
    app.connect("autodoc-process-docstring", _process, priority=400)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
