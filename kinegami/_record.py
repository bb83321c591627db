"""Light named tuples: what ``typing.NamedTuple`` gives, at a fiftieth of its import cost.

``typing.NamedTuple`` builds each class with ``exec`` and compiles every (postponed) field
annotation, about half a millisecond per class; the pattern modules define a dozen, which the
first ``creasePattern()`` of a process would pay (docs/architecture.md, "Start-up cost"). A
:class:`Record` subclass is declared the same way and behaves the same for its users (a tuple
with named, read-only fields, defaults, ``_fields``, ``_replace``, ``_asdict``, a repr and
pickling) but is built with one ``property`` per field.

>>> class Point(Record):
...     x: float
...     y: float = 0.0
>>> p = Point(1.5)
>>> p, p.x, tuple(p), p._replace(y=2.0)
(Point(x=1.5, y=0.0), 1.5, (1.5, 0.0), Point(x=1.5, y=2.0))
"""

from __future__ import annotations

from operator import itemgetter
from typing import Any

__all__ = ["Record"]


class _RecordType(type):
    """Gives every Record class ``__slots__ = ()`` (instances as small as tuples, no
    ``__dict__``), as ``typing.NamedTuple`` does."""

    def __new__(mcls, name, bases, namespace, **kwargs):
        namespace.setdefault("__slots__", ())
        return super().__new__(mcls, name, bases, namespace, **kwargs)


class Record(tuple, metaclass=_RecordType):
    """Base of light named tuples: subclass it with annotated fields (and optional defaults,
    which must follow the fields without one), as for ``typing.NamedTuple``."""

    __slots__ = ()
    _fields: tuple[str, ...] = ()
    _field_defaults: dict[str, Any] = {}

    def __init_subclass__(cls, **kwargs) -> None:
        super().__init_subclass__(**kwargs)
        own = [name for name in cls.__dict__.get("__annotations__", {}) if not name.startswith("_")]
        if not own:
            return
        fields = cls._fields + tuple(own)
        defaults = dict(cls._field_defaults)
        for name in own:
            if name in cls.__dict__:
                defaults[name] = cls.__dict__[name]
            elif defaults:
                raise TypeError(f"{cls.__name__}: field {name!r} needs a default (it follows one)")
        for i, name in enumerate(own, start=len(cls._fields)):
            setattr(cls, name, property(itemgetter(i), doc=f"Field {i}: {name}."))
        cls._fields, cls._field_defaults = fields, defaults

    def __new__(cls, *args, **kwargs):
        fields = cls._fields
        if len(args) == len(fields) and not kwargs:
            return tuple.__new__(cls, args)
        if len(args) > len(fields):
            raise TypeError(f"{cls.__name__} takes {len(fields)} fields, got {len(args)}")
        values = list(args)
        for name in fields[len(args) :]:
            if name in kwargs:
                values.append(kwargs.pop(name))
            elif name in cls._field_defaults:
                values.append(cls._field_defaults[name])
            else:
                raise TypeError(f"{cls.__name__} is missing the field {name!r}")
        if kwargs:
            raise TypeError(f"{cls.__name__} got unexpected or repeated fields {sorted(kwargs)}")
        return tuple.__new__(cls, values)

    def __getnewargs__(self) -> tuple:
        return tuple(self)

    def __repr__(self) -> str:
        pairs = zip(self._fields, self, strict=True)
        inner = ", ".join(f"{name}={value!r}" for name, value in pairs)
        return f"{type(self).__name__}({inner})"

    def _replace(self, **changes) -> Record:
        """A copy with the named fields changed."""
        return type(self)(**{**self._asdict(), **changes})

    def _asdict(self) -> dict[str, Any]:
        """The fields as a dict, in order."""
        return dict(zip(self._fields, self, strict=True))
