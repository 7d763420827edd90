"""Read access by field name for the solvers' frozen batch records (NormalBatch, CoupledBatch, RkgBatch).

The batch records replaced dicts; their callers still read ``batch["e_n"]``, iterate over the names
and take ``len``. One mixin gives every record that protocol from its dataclass fields.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields

__all__ = ["ReadableByName"]


class ReadableByName(Mapping):
    """A dataclass read as a mapping of its field names (``record[name]``, ``iter``, ``len``, ``keys``, ``get``).

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True)
    ... class Pair(ReadableByName):
    ...     a: int
    ...     b: int
    >>> p = Pair(1, 2)
    >>> p["b"], list(p), len(p), dict(p)
    (2, ['a', 'b'], 2, {'a': 1, 'b': 2})
    >>> p["c"]
    Traceback (most recent call last):
    ...
    KeyError: 'c'
    """

    __slots__ = ()

    def __getitem__(self, name: str):
        if name not in _names(type(self)):
            raise KeyError(name)
        return getattr(self, name)

    def __iter__(self):
        return iter(_names(type(self)))

    def __len__(self) -> int:
        return len(_names(type(self)))


def _names(cls) -> tuple[str, ...]:
    """The field names of dataclass ``cls``, in order."""
    return tuple(f.name for f in fields(cls))
