"""Callback interfaces: a plain function that declares its outcomes and keys."""

from typing import Any, Callable, Iterable


class CBInterface:
    """Decorated callback: callable, and carries SMACH's three ``get_registered_*`` getters."""

    def __init__(self, cb: Callable[..., Any], outcomes: Iterable[str] | None = None,
                 input_keys: Iterable[str] | None = None, output_keys: Iterable[str] | None = None,
                 io_keys: Iterable[str] | None = None) -> None:
        self._cb = cb
        self._outcomes = list(outcomes or ())  # in the order given, as SMACH
        # Fixed against SMACH: io_keys count as both input and output keys.
        self._input_keys = set(input_keys or ()) | set(io_keys or ())
        self._output_keys = set(output_keys or ()) | set(io_keys or ())
        self.__name__ = getattr(cb, "__name__", type(cb).__name__)
        self.__doc__ = getattr(cb, "__doc__", None)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self._cb(*args, **kwargs)

    def get_registered_input_keys(self) -> tuple:
        return tuple(self._input_keys)

    def get_registered_output_keys(self) -> tuple:
        return tuple(self._output_keys)

    def get_registered_outcomes(self) -> tuple:
        return tuple(self._outcomes)


def cb_interface(outcomes: Iterable[str] | None = None, input_keys: Iterable[str] | None = None,
                 output_keys: Iterable[str] | None = None) -> Callable[[Callable[..., Any]], CBInterface]:
    """Decorator form of CBInterface (no io_keys parameter, as in SMACH)."""
    def decorator(cb: Callable[..., Any]) -> CBInterface:
        return CBInterface(cb, outcomes, input_keys, output_keys)
    return decorator


def has_smach_interface(obj: Any) -> bool:
    return (hasattr(obj, "get_registered_input_keys") and hasattr(obj, "get_registered_output_keys")
            and hasattr(obj, "get_registered_outcomes"))
