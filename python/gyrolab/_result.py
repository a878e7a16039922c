"""A command's answer: the command line's JSON keys as items and
attributes (lists of numbers as numpy arrays), its text, its report (a
notebook shows it), and what the command writes beside it (a model file's
text, the compensated run)."""

import json

import numpy as np


def _is_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) or x is None


def _arrays(v):
    """JSON values with non-empty lists of numbers (and lists of such
    lists) as float arrays (null as NaN); other values as they are."""
    if isinstance(v, dict):
        return {k: _arrays(x) for k, x in v.items()}
    if isinstance(v, list):
        if all(_is_number(x) for x in v) and any(x is not None for x in v):
            return np.array([np.nan if x is None else x for x in v], dtype=float)
        if v and all(
            isinstance(x, list) and x and all(_is_number(y) for y in x) for x in v
        ) and len({len(x) for x in v}) == 1:
            return np.array(
                [[np.nan if y is None else y for y in x] for x in v], dtype=float
            )
        # An empty list stays a list: `found == []` reads as nothing found.
        return [_arrays(x) for x in v]
    return v


class Result:
    """What a gyrolab command found. ``r["key"]`` and ``r.key`` give the
    command line's ``--json`` keys; ``r.to_json()`` is its JSON line,
    ``r.text`` its text; in a notebook ``r`` shows its report
    (``r.html`` is the report as a page to save)."""

    def __init__(self, command, native, extras=None):
        self._command = command
        self._json = native.json()
        self._data = _arrays(json.loads(self._json))
        self._text = list(native.text())
        self._summary = list(native.summary())
        self._native = native
        self._html = None
        self._extras = dict(extras or {})

    # The JSON's keys.
    def __getitem__(self, key):
        return self._data[key]

    def __contains__(self, key):
        return key in self._data

    def __iter__(self):
        return iter(self._data)

    def __len__(self):
        return len(self._data)

    def keys(self):
        return self._data.keys()

    def items(self):
        return self._data.items()

    def get(self, key, default=None):
        return self._data.get(key, default)

    def __getattr__(self, name):
        if name.startswith("__") or name in ("_data", "_extras"):
            raise AttributeError(name)
        if name in self._extras:
            return self._extras[name]
        try:
            return self._data[name]
        except KeyError:
            raise AttributeError(
                "%s result has no %r (its keys: %s)"
                % (self._command, name, ", ".join(sorted(self._data)))
            ) from None

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self._data) | set(self._extras))

    def to_json(self):
        """The command line's JSON object, as its text (one line)."""
        return self._json

    def to_dict(self):
        """The JSON object as Python's plain values (lists, not arrays)."""
        return json.loads(self._json)

    @property
    def command(self):
        return self._command

    @property
    def text(self):
        """What the command line prints, as text."""
        return "\n".join(self._text)

    def _report(self):
        if self._html is None:
            page = self._native.html() if self._native is not None else None
            frag = self._native.fragment() if self._native is not None else None
            self._html = (page, frag)
        return self._html

    @property
    def html(self):
        """The report as a self-contained HTML page (None where the
        command has none)."""
        return self._report()[0]

    def _repr_html_(self):
        return self._report()[1]

    def __repr__(self):
        lines = ["<gyrolab.%s>" % self._command] + ["  " + s for s in self._summary]
        return "\n".join(lines)

    # Pickling: the report made, the native object left behind.
    def __getstate__(self):
        page, frag = self._report()
        return {
            "command": self._command,
            "json": self._json,
            "text": self._text,
            "summary": self._summary,
            "html": (page, frag),
            "extras": self._extras,
        }

    def __setstate__(self, s):
        self._command = s["command"]
        self._json = s["json"]
        self._data = _arrays(json.loads(self._json))
        self._text = s["text"]
        self._summary = s["summary"]
        self._native = None
        self._html = s["html"]
        self._extras = s["extras"]
