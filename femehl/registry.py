"""One registry helper for every plug-in kind: a name -> class map whose ``register`` is the
class decorator that adds a class (docs/design.md section 8)."""

from __future__ import annotations

__all__ = ["Registry"]


class Registry(dict):
    """``name -> class`` of one plug-in kind (substrates, methods, terms, ...).

    ``key``: the class attribute that names a class (``kind``, ``name``); without it the
    name is given to the decorator, ``@REGISTRY.register("fe")``, and set on the class as
    ``stamp`` (``method``, ``name``).  ``register`` returns the class unchanged.
    """

    def __init__(self, what: str, key: str | None = None, stamp: str | None = None):
        super().__init__()
        self.what, self.key, self.stamp = what, key, stamp

    def register(self, cls_or_name):
        if isinstance(cls_or_name, str):
            name = cls_or_name

            def deco(cls):
                if self.stamp is not None:
                    setattr(cls, self.stamp, name)
                self[name] = cls
                return cls

            return deco
        cls = cls_or_name
        self[getattr(cls, self.key)] = cls
        return cls

    def __repr__(self) -> str:
        return f"Registry({self.what}: {sorted(self)})"
