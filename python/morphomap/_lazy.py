"""Names of a package that are imported from their submodule when first used (PEP 562)."""

from __future__ import annotations

from importlib import import_module


def lazy_names(package: str, namespace: dict, submodules: dict):
    """``(__getattr__, __dir__)`` for ``package``, whose ``namespace`` (its ``globals()``) lacks
    the names of ``submodules`` (``{submodule: (name, ...)}``) until one of them is asked for:
    then its submodule is imported and the name kept in the namespace. The submodules themselves
    are attributes too, imported on first use."""
    home = {name: module for module, names in submodules.items() for name in names}

    def __getattr__(name: str):
        if name in submodules:
            return import_module(f".{name}", package)
        if name not in home:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(import_module(f".{home[name]}", package), name)
        namespace[name] = value
        return value

    def __dir__() -> list:
        return sorted(set(namespace) | set(home) | set(submodules))

    return __getattr__, __dir__
