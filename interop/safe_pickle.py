"""SMACH's userdata as smach_ros pickles it (``local_data``), read without running anything.

smach_viewer calls ``pickle.loads`` on what arrives, which runs whatever the bytes say. Here the
unpickler builds plain data only (dict, list, tuple, set, str, bytes, int, float, bool, None) and
every global a pickle names (a class, a ROS message, a numpy array, ``os.system``) becomes an
``Opaque`` marker with its name: calling one, building one or setting its state makes another
marker, never the real thing. The few globals that plain data itself needs under pickle protocol 2
(``set``, ``frozenset``, ``bytes``, ``bytearray``, ``OrderedDict``, ``_codecs.encode``) build what
they would with their arguments checked.
"""

from __future__ import annotations

import base64
import binascii
import collections
import io
import pickle
from typing import Any

MAX_BYTES = 16 << 20  # a userdata pickle bigger than this is not read


class Opaque:
    """What a pickle built from a global this module does not trust: its name, nothing else."""

    type_name = "?"

    def __new__(cls, *args: Any, **kwargs: Any) -> Opaque:
        return object.__new__(cls)

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        pass

    def __setstate__(self, state: Any) -> None:
        pass  # its fields are not kept: they could hold anything

    def __call__(self, *args: Any, **kwargs: Any) -> Opaque:
        return _marker(self.type_name + "(...)")()

    def __repr__(self) -> str:
        return "<opaque %s>" % self.type_name


def _marker(name: str) -> type[Opaque]:
    return type("Opaque", (Opaque,), {"type_name": name})


def _codecs_encode(text: Any, codec: str = "utf-8") -> bytes | Opaque:
    """Protocol 2 writes Python 3 bytes as ``_codecs.encode(str, 'latin1')``."""
    if isinstance(text, str) and codec in ("latin1", "latin-1"):
        return text.encode("latin1")
    return _marker("_codecs.encode")()


def _of(kind: type) -> Any:
    """``kind`` built from a collection (never from a number: ``bytes(10**12)`` would allocate it)."""
    def build(items: Any = ()) -> Any:
        if isinstance(items, (list, tuple, set, frozenset, dict, str, bytes, bytearray)):
            try:
                return kind(items)
            except (TypeError, ValueError):  # unhashable items, str to bytes without a codec, ...
                pass
        return _marker(kind.__name__)()
    return build


def _reconstructor(cls: Any, base: Any = None, state: Any = None) -> Opaque:
    """copyreg's way of pickling a plain class instance: the marker says the class, not copyreg."""
    return cls() if isinstance(cls, type) and issubclass(cls, Opaque) else _marker("copyreg._reconstructor")()


_PLAIN = {
    ("builtins", "set"): _of(set), ("__builtin__", "set"): _of(set),
    ("builtins", "frozenset"): _of(frozenset), ("__builtin__", "frozenset"): _of(frozenset),
    ("builtins", "bytearray"): _of(bytearray), ("__builtin__", "bytearray"): _of(bytearray),
    ("builtins", "bytes"): _of(bytes), ("__builtin__", "bytes"): _of(bytes),
    ("collections", "OrderedDict"): _of(collections.OrderedDict),
    ("_codecs", "encode"): _codecs_encode,
    ("copyreg", "_reconstructor"): _reconstructor, ("copy_reg", "_reconstructor"): _reconstructor,
}


class _Unpickler(pickle.Unpickler):
    def find_class(self, module: str, name: str) -> Any:
        return _PLAIN.get((module, name)) or _marker("%s.%s" % (module, name))

    def persistent_load(self, pid: Any) -> Opaque:
        return _marker("persistent id")()


def loads(data: bytes) -> Any:
    """The value a pickle holds, plain data and ``Opaque`` markers only. Raises ``pickle.UnpicklingError``
    (or ``ValueError``, ``EOFError``) for bytes that are no pickle."""
    if len(data) > MAX_BYTES:
        raise ValueError("a pickle of %d bytes, above the limit of %d" % (len(data), MAX_BYTES))
    return _Unpickler(io.BytesIO(data), encoding="latin1").load()  # latin1: Python 2's str pickles


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
        except Exception as exc:  # any malformed pickle: the next form, then the caller says so
            failure = exc
    raise ValueError("local_data is no pickle: %s: %s" % (type(failure).__name__, failure))
