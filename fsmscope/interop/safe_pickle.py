"""SMACH's userdata as smach_ros pickles it (``local_data``), read without running anything.

smach_viewer calls ``pickle.loads`` on what arrives, which runs whatever the bytes say. Here the
unpickler builds plain data only (dict, list, tuple, set, str, bytes, int, float, bool, None) and
every global a pickle names (a class, a ROS message, a numpy array, ``os.system``) becomes an
``Opaque`` marker with its name: calling one, building one or setting its state makes another
marker, never the real thing. The few globals that plain data itself needs under pickle protocol 2
(``set``, ``frozenset``, ``bytes``, ``bytearray``, ``OrderedDict``, ``_codecs.encode``) build what
they would with their arguments checked.

What it builds costs no more than its bytes say: the unpickler is pickle's own in Python
(``pickle._Unpickler``, the standard library's fallback, about 2.5 times slower than the C one),
so that the steps which hash a value (a dict's key, a set's item) count what hashing reads
against one budget per pickle first (``HASHED_PER_BYTE`` steps per byte): a key of shared references (a tuple of ten references to a
tuple of ten references to ..., a few hundred bytes that hashing reads 10^40 times) or one
nested deep enough to overflow the C stack is refused, as is the pickle. A pickle names at most
``MAX_NAMES`` globals with a marker class of their own.
"""

from __future__ import annotations

import base64
import binascii
import collections
import functools
import io
import pickle
from typing import Any, Callable

MAX_BYTES = 16 << 20  # a userdata pickle bigger than this is not read
# Steps that hashing the dict keys and set items of one pickle may take, in all: so many per byte of
# the pickle (each part of a key that is not shared takes a byte of it at least), a million at least.
HASHED_PER_BYTE = 4
MIN_HASHED = 1 << 20
MAX_KEY_DEPTH = 64  # nesting of a dict key or set item (hashing it recurses on the C stack)
MAX_NAMES = 256  # globals of one pickle with a marker class of their own; the next ones share one


_KEPT_PARTS = 16  # a key of so many parts is counted once and remembered (a shared one is met again)
_TOO_DEEP = "a pickle with a dict key or set item nested deeper than %d levels" % MAX_KEY_DEPTH


class TooCostly(ValueError):
    """A pickle whose value would cost much more to build than its bytes; the message says why."""


class Opaque:
    """What a pickle built from a global this module does not trust: its name, nothing else."""

    type_name = "?"
    _markers: Callable[[str], type[Opaque]]  # the pickle's markers by name (``_Unpickler.marker``)

    def __new__(cls, *args: Any, **kwargs: Any) -> Opaque:
        return object.__new__(cls)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        pass

    def __setstate__(self, state: Any) -> None:
        pass  # its fields are not kept: they could hold anything

    def __call__(self, *args: Any, **kwargs: Any) -> Opaque:
        called = self.type_name if self.type_name.endswith("(...)") else self.type_name + "(...)"
        return self._markers(called)()

    def __repr__(self) -> str:
        return "<opaque %s>" % self.type_name


@functools.lru_cache(maxsize=None)  # the names below, fixed in this module
def _marker(name: str) -> type[Opaque]:
    return type("Opaque", (Opaque,), {"type_name": name, "_markers": staticmethod(_marker)})


def _codecs_encode(loading: _Unpickler, text: Any, codec: str = "utf-8") -> bytes | Opaque:
    """Protocol 2 writes Python 3 bytes as ``_codecs.encode(str, 'latin1')``."""
    if isinstance(text, str) and codec in ("latin1", "latin-1"):
        return text.encode("latin1")
    return _marker("_codecs.encode")()


def _of(kind: type, hashes: bool = False) -> Callable[..., Any]:
    """``kind`` built from a collection (never from a number: ``bytes(10**12)`` would allocate it);
    when ``hashes``, its items (or keys) counted against the pickle's budget first."""
    def build(loading: _Unpickler, items: Any = ()) -> Any:
        if isinstance(items, (list, tuple, set, frozenset, dict, str, bytes, bytearray)):
            if hashes:
                pairs = kind is collections.OrderedDict and not isinstance(items, dict)
                for item in items:
                    if not pairs:
                        loading.hashing(item)
                    elif isinstance(item, (tuple, list)) and len(item) == 2:
                        loading.hashing(item[0])
            try:
                return kind(items)
            except (TypeError, ValueError):  # unhashable items, str to bytes without a codec, ...
                pass
        return _marker(kind.__name__)()
    return build


def _reconstructor(loading: _Unpickler, cls: Any, base: Any = None, state: Any = None) -> Opaque:
    """copyreg's way of pickling a plain class instance: the marker says the class, not copyreg."""
    return cls() if isinstance(cls, type) and issubclass(cls, Opaque) else _marker("copyreg._reconstructor")()


_PLAIN = {
    ("builtins", "set"): _of(set, True), ("__builtin__", "set"): _of(set, True),
    ("builtins", "frozenset"): _of(frozenset, True), ("__builtin__", "frozenset"): _of(frozenset, True),
    ("builtins", "bytearray"): _of(bytearray), ("__builtin__", "bytearray"): _of(bytearray),
    ("builtins", "bytes"): _of(bytes), ("__builtin__", "bytes"): _of(bytes),
    ("collections", "OrderedDict"): _of(collections.OrderedDict, True),
    ("_codecs", "encode"): _codecs_encode,
    ("copyreg", "_reconstructor"): _reconstructor, ("copy_reg", "_reconstructor"): _reconstructor,
}


class _Unpickler(pickle._Unpickler):
    """pickle's unpickler in Python, with every step that hashes a value counting it first."""

    dispatch = dict(pickle._Unpickler.dispatch)

    def __init__(self, data: bytes) -> None:
        super().__init__(io.BytesIO(data), encoding="latin1")  # latin1: Python 2's str pickles
        self.hashed = 0
        self.budget = max(MIN_HASHED, HASHED_PER_BYTE * len(data))
        self.parts: dict[int, tuple[Any, int, int]] = {}  # id -> (a big key, its parts, its nesting)
        self.markers: dict[str, type[Opaque]] = {}

    def find_class(self, module: str, name: str) -> Any:
        plain = _PLAIN.get((module, name))
        return functools.partial(plain, self) if plain is not None else self.marker("%s.%s" % (module, name))

    def persistent_load(self, pid: Any) -> Opaque:
        return _marker("persistent id")()

    def marker(self, name: str) -> type[Opaque]:
        """The marker class of a global's name, one per name (the ``MAX_NAMES``-th and after: one for all)."""
        made = self.markers.get(name)
        if made is None:
            if len(self.markers) >= MAX_NAMES:
                return _marker("(one of more than %d globals)" % MAX_NAMES)
            made = self.markers[name] = type("Opaque", (Opaque,), {"type_name": name, "_markers": self.marker})
        return made

    def hashing(self, key: Any) -> None:
        """``key`` is about to be hashed: what hashing reads is counted; TooCostly when over the budget."""
        self.hashed += self._parts(key, 0)[0]
        if self.hashed > self.budget:
            raise TooCostly("a pickle whose dict keys and set items would take hashing more than %d steps"
                            % self.budget)

    def _parts(self, key: Any, depth: int) -> tuple[int, int]:
        """(what hashing ``key`` reads, its nesting): a tuple or frozenset each time it is hashed
        (a frozenset keeps its hash, counted again all the same), a long int by its length."""
        t = type(key)
        if t is not tuple and t is not frozenset:
            return (1 + key.bit_length() // 4096 if t is int else 1), 0
        known = self.parts.get(id(key))
        if known is None:
            if depth > MAX_KEY_DEPTH:
                raise TooCostly(_TOO_DEEP)
            parts, nesting = 1, 0
            for item in key:
                inner = self._parts(item, depth + 1)
                parts, nesting = min(parts + inner[0], self.budget + 1), max(nesting, inner[1] + 1)
            known = (key, parts, nesting)
            if parts >= _KEPT_PARTS:
                self.parts[id(key)] = known  # the key held: its id is not reused meanwhile
        if depth + known[2] > MAX_KEY_DEPTH:
            raise TooCostly(_TOO_DEEP)
        return known[1], known[2]

    def load_setitem(self) -> None:
        self.hashing(self.stack[-2])
        super().load_setitem()

    # After a MARK, ``self.stack`` holds the items since the mark alone (pickle._Unpickler.pop_mark).
    def load_setitems(self) -> None:
        for key in self.stack[::2]:
            self.hashing(key)
        super().load_setitems()

    def load_additems(self) -> None:
        for item in self.stack:
            self.hashing(item)
        super().load_additems()

    def load_frozenset(self) -> None:
        for item in self.stack:
            self.hashing(item)
        super().load_frozenset()

    for _op, _load in ((pickle.SETITEM, load_setitem), (pickle.SETITEMS, load_setitems),
                       (pickle.ADDITEMS, load_additems), (pickle.FROZENSET, load_frozenset)):
        dispatch[_op[0]] = _load
    del _op, _load


def loads(data: bytes) -> Any:
    """The value a pickle holds, plain data and ``Opaque`` markers only. Raises ``pickle.UnpicklingError``
    (or ``ValueError``, ``EOFError``) for bytes that are no pickle, ``TooCostly`` for one whose value
    would cost much more than its bytes."""
    if len(data) > MAX_BYTES:
        raise ValueError("a pickle of %d bytes, above the limit of %d" % (len(data), MAX_BYTES))
    return _Unpickler(data).load()


def local_data(raw: str | bytes) -> Any:
    """``local_data`` of a SmachContainerStatus in any of its forms: base64 of a protocol 2 pickle
    (smach_ros on noetic), the pickle itself (older releases, and ROS 2's ``uint8[]``)."""
    blob = raw.encode("utf-8", "surrogateescape") if isinstance(raw, str) else bytes(raw)
    tries = []
    try:
        tries.append(base64.b64decode(blob, validate=True))  # a pickle starts with 0x80: never base64
    except (binascii.Error, ValueError):
        pass
    tries.append(blob)
    failure: Exception | None = None
    for data in tries:
        try:
            return loads(data)
        except TooCostly:
            raise
        except Exception as exc:  # any malformed pickle: the next form, then the caller says so
            failure = exc
    raise ValueError("local_data is no pickle: %s: %s" % (type(failure).__name__, failure))
