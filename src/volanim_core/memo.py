"""A few recent results, kept by a hash of what they depend on (thread-safe).

    content_key(arrays..., text) --blake2b--> 16 bytes
    Recent(n).get(key, make) --hit: the kept result (now most recent) / miss: make(), kept, oldest dropped

Why a hash of the content and not the object: a caller reconstructing frame after frame, or the
studio building a fresh connectivity for each preview, hands in new objects holding the same
points; the sphere neighbour lists and the smooth-joint weights made for the first must serve them all.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import Any

import numpy as np


def content_key(*parts, text: str = "") -> bytes:
    """16 bytes that change when any array's bytes (in its own dtype) or ``text`` change."""
    h = hashlib.blake2b(digest_size=16)
    h.update(text.encode())
    for part in parts:
        a = np.ascontiguousarray(part)
        h.update(a.dtype.str.encode() + str(a.shape).encode())
        h.update(a.tobytes())
    return h.digest()


class Recent:
    """The last ``size`` results by key: ``get(key, make)`` returns the kept one or makes and keeps it.
    ``make`` runs outside the lock, so two threads missing at once both make it (same result)."""

    def __init__(self, size: int):
        self.size = size
        self._items: OrderedDict[bytes, Any] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: bytes, make: Callable[[], Any]) -> Any:
        with self._lock:
            if key in self._items:
                self._items.move_to_end(key)
                return self._items[key]
        value = make()
        with self._lock:
            self._items[key] = value
            while len(self._items) > self.size:
                self._items.popitem(last=False)
        return value
