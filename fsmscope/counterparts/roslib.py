"""roslib, ROS-free (loaded under the name ``roslib``): ``load_manifest``, which old scripts call
first, does nothing (there is no package path to extend)."""

from typing import Any

from fsmscope.counterparts.names import not_covered

__all__ = ["load_manifest"]


def load_manifest(package_name: str, bootstrap_version: str = "0.7") -> None:
    return None


def __getattr__(name: str) -> Any:
    raise not_covered("roslib", name, __all__)
