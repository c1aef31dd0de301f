"""One bounded in-memory cache for values derived from other objects (grids, indices,
part sets), instead of an ad-hoc module dict in each place.

Keys are hashable tuples. An *owner* object may stand in the key by identity (``id``):
the cache then holds the owner, so its id cannot be reused by another object while the
entry lives, and a hit is checked with ``is``. When full, the oldest entry goes first.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

__all__ = ["BoundedCache"]

V = TypeVar("V")


class BoundedCache(Generic[V]):
    """At most ``maxsize`` values, by key and (optionally) by the identity of an owner.

    Parameters
    ----------
    maxsize : int
        Entries kept; adding one more drops the oldest.
    """

    def __init__(self, maxsize: int) -> None:
        if maxsize < 1:
            raise ValueError(f"BoundedCache: maxsize must be >= 1, got {maxsize}")
        self.maxsize = maxsize
        self._entries: dict[Hashable, tuple[object, V]] = {}

    def __len__(self) -> int:
        return len(self._entries)

    def clear(self) -> None:
        """Drop every entry."""
        self._entries.clear()

    def get(self, key: Hashable, owner: object = None) -> V | None:
        """The value stored under ``key`` (and ``owner``, by identity), or None."""
        hit = self._entries.get(self._key(key, owner))
        if hit is None or hit[0] is not owner:
            return None
        return hit[1]

    def put(self, key: Hashable, value: V, owner: object = None) -> V:
        """Store ``value`` under ``key`` (and ``owner``); returns ``value``."""
        full = self._key(key, owner)
        if full not in self._entries and len(self._entries) >= self.maxsize:
            self._entries.pop(next(iter(self._entries)))
        self._entries[full] = (owner, value)
        return value

    def get_or_build(self, key: Hashable, build: Callable[[], V], owner: object = None) -> V:
        """The cached value, or ``build()`` stored and returned."""
        value = self.get(key, owner)
        return self.put(key, build(), owner) if value is None else value

    @staticmethod
    def _key(key: Hashable, owner: object) -> Hashable:
        return key if owner is None else (id(owner), key)
