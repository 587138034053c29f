"""One lazy package face (PEP 562) for every package of the project: public names imported on
first use, so that importing a package costs nothing until a name is used.

Lives in ``reference`` (the bottom of the import order) so that ``cardan_exudyn`` and
``rigdata`` faces can use it too; it imports only the standard library.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_face"]


def lazy_face(package: str, homes: Mapping[str, str]) -> tuple[Callable[[str], Any],
                                                                Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for ``package``'s ``__init__``.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    homes : mapping
        Public name -> the module that defines it; a name whose home is the module
        ``<package>.<name>`` itself (``"sweep": "cardan_exudyn.sweep"``) is that module.

    Returns
    -------
    (__getattr__, __dir__)
        Assign both at module level. A name is looked up once and then cached in the package.
    """
    def __getattr__(name: str) -> Any:
        home = homes.get(name)
        if home is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module = importlib.import_module(home)
        value = module if home == f"{package}.{name}" else getattr(module, name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(homes))

    return __getattr__, __dir__
