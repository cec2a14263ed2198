"""A skin: each blended point's bones and weights (what :mod:`.skinning` makes and :mod:`.thin_spheres` mends).

Its own module, below both, so the rule that makes the weights and the rule that copies them to the
one-voxel spheres import the type and never each other.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

INFLUENCES = 4  # bones per point at most: its own and three neighbours' (a fork's bone near two children)


@dataclass(frozen=True)
class Skin:
    """Blend weights of the points that have any: ``index`` (K,) point indices, ``influence`` (K, J)
    bone indices (the point's own bone first, -1 padding) and ``weight`` (K, J), each row summing to 1.

    ``sheet``: the blended points on a medial sheet, whose radii follow its stretch (:func:`posed_radii`);
    ``pairs`` (L, 2): their links (point indices), ``rest`` (L,): the links' rest lengths."""

    index: np.ndarray
    influence: np.ndarray
    weight: np.ndarray
    sheet: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    pairs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    rest: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __len__(self) -> int:
        return len(self.index)

    def take(self, order: np.ndarray, n: int) -> Skin:
        """The skin of ``points[order]`` (a permutation or subset of ``n`` points)."""
        order = np.asarray(order)
        row = np.full(n, -1, np.int64)
        row[self.index] = np.arange(len(self.index))
        picked = row[order]
        keep = np.flatnonzero(picked >= 0)
        at = np.full(n, -1, np.int64)  # each old point's place in the new order
        at[order] = np.arange(len(order))
        sheet = at[self.sheet]
        pairs = at[self.pairs]
        both = (pairs >= 0).all(axis=1)
        return Skin(keep.astype(np.int64), self.influence[picked[keep]], self.weight[picked[keep]],
                    np.sort(sheet[sheet >= 0]), pairs[both], self.rest[both])
