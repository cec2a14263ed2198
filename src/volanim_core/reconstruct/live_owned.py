"""Only what moved, by bone: an owned frame after a pose edit redoes only the box the moved bones reach (#85).

    LiveOwned(ownership, bounds, mode)
      .update(matrices) --compared with the last frame's--> the bones whose matrix changed
                        --their posed boxes and joint balls, before the edit and after it--> one box
                        --reconstruct_owned(bounds=that box)--> pasted into the kept frame --> Reconstruction

Why this is exact: an output voxel of :func:`~volanim_core.reconstruct.owned.reconstruct_owned` is decided by
the bones whose posed box (their owned voxels' hull, moved) or joint ball holds it -- the read from the rest
voxel each brings it back to, the splat of a turned bone's voxels, the ball -- and a bounded call decides each
voxel of its box as the whole frame does (the tests compare them). A voxel outside every moved bone's boxes
and balls, before and after, is decided by the same bones at the same places and keeps its value. A ball that
two bones carry to one place is drawn for the first of them: when the first moves, the other's is drawn
there, inside the moved bone's old ball.

A drag turns one bone and its descendants: on the mannequin a raised forearm redoes its own box, not the body.
The grid is fixed (``bounds``): what a pose carries out of it is clipped (``stats['clipped']``), as
``reconstruct(bounds=...)`` does.
"""

from __future__ import annotations

import time

import numpy as np

from volanim_core.progress import Clock
from volanim_core.reconstruct.owned import joint_balls, posed_boxes, reconstruct_owned
from volanim_core.reconstruct.result import Reconstruction
from volanim_core.rig.ownership import Ownership
from volanim_core.volume import Bounds

ONE_THREAD_VOXELS = 1 << 20  # a box redone below this many voxels is redone on one thread


class LiveOwned:
    """Frames of one ownership on one grid, each after the last: :meth:`update` redoes the box the bones that
    moved reach and returns what ``reconstruct_owned(own, matrices, mode=mode, bounds=bounds)`` would.

    ``matrices`` take :attr:`own`'s rest voxels to posed ones (:meth:`Ownership.rest_matrices` for a coarse one).
    """

    def __init__(self, own: Ownership, bounds: Bounds, *, mode: str = "bone", value: int = 255,
                 threads: int | None = None, clock: Clock = time.perf_counter):
        self.own, self.bounds, self.mode, self.value = own, bounds, mode, value
        self.threads, self.clock = threads, clock
        self._frame: Reconstruction | None = None
        self._matrices: np.ndarray | None = None
        self._owners = np.empty(0, own.labels.dtype)  # a moved box's owners: the grid's size, made once
        self.redone = 0  # voxels the last update decided again (the whole grid's on a first frame)
        # the grid's z-slices the last update may have changed: (first, last), None (none) or "all" (a first frame)
        self.changed: tuple[int, int] | None | str = "all"

    def update(self, matrices: np.ndarray, *, copy: bool = True) -> Reconstruction:
        """The frame posed by ``matrices`` on the fixed grid. ``copy=False`` returns the kept frame itself:
        cheaper, but the next update overwrites it (draw it, then let it go)."""
        t0 = self.clock()
        m = np.ascontiguousarray(matrices, np.float64)
        if self._frame is None:
            self._frame = self._made(m, self.bounds)
            self.redone, self.changed = int(np.prod(self.bounds.shape)), "all"
        else:
            box = self._moved_box(self._matrices, m)
            self.redone = 0 if box is None else int(np.prod(box.shape))
            self.changed = None
            if box is not None:
                self._paste(self._made(m, box, kept=True), box)
                z = self._frame.origin[2]
                self.changed = (box.lo[2] - z, box.hi[2] - z)
        self._matrices = m
        f = self._frame
        stats = {**f.stats, "seconds": self.clock() - t0, "redone": self.redone,
                 "clipped": _clipped(self.own, m, self.bounds)}
        volume = f.volume.copy(order="K") if copy else f.volume
        return Reconstruction(volume, f.origin, stats, f.geometry)

    def _made(self, matrices: np.ndarray, bounds: Bounds, kept: bool = False) -> Reconstruction:
        """The frame within ``bounds``; ``kept``: its owners in this object's own array, which the next call
        overwrites (a moved box, pasted at once: a fresh array a picture cost page faults on every voxel)."""
        # a small box on one thread: the kernels' thread barriers cost more than its voxels (a forearm's box
        # on the mannequin: 9 ms on one thread, 21 ms on two, with the machine busy)
        n = int(np.prod(bounds.shape, dtype=np.int64))
        owners = None
        if kept:
            if self._owners.size < n:  # the grid's size at once: a drag's box grows as it sweeps, and each larger
                self._owners = np.empty(int(np.prod(self.bounds.shape)), self.own.labels.dtype)  # array faulted anew
            owners = self._owners[:n].reshape(bounds.shape[::-1])
        return reconstruct_owned(self.own, matrices, mode=self.mode, bounds=bounds, value=self.value,
                                 threads=1 if n < ONE_THREAD_VOXELS else self.threads, clock=self.clock, owners=owners)

    def _moved_box(self, old: np.ndarray, new: np.ndarray) -> Bounds | None:
        """The box of every voxel the bones whose matrix changed can decide, in either pose; None: none moved."""
        moved = np.flatnonzero(np.any(old != new, axis=(1, 2)))
        if not len(moved):
            return None
        los, his = [], []
        for m in (old, new):
            boxes = posed_boxes(self.own, m)[moved]
            has = boxes[:, 3] >= boxes[:, 0]
            los.append(boxes[has, :3])
            his.append(boxes[has, 3:])
            centres, r2s, ball_bones = joint_balls(self.own, m)
            # every ball a moved bone carries, and the ball drawn where it was (another bone's, once it moves)
            mine = np.isin(ball_bones, moved) | _at_moved_joints(self.own, m, moved, centres)
            r = np.sqrt(r2s[mine])[:, None]
            los.append(np.floor(centres[mine] - r).astype(np.int64) - 1)
            his.append(np.ceil(centres[mine] + r).astype(np.int64) + 1)
        lo = np.maximum(np.concatenate(los).min(0), self.bounds.lo)
        hi = np.minimum(np.concatenate(his).max(0), self.bounds.hi)
        if (hi < lo).any():
            return None  # moved wholly outside the grid, before and after
        return Bounds(tuple(int(v) for v in lo), tuple(int(v) for v in hi))

    def _paste(self, part: Reconstruction, box: Bounds) -> None:
        f = self._frame
        at = tuple(slice(a - o, b - o + 1) for a, b, o in zip(box.lo, box.hi, f.origin))
        before = int(np.count_nonzero(f.volume[at]))
        f.volume[at] = part.volume
        filled = f.stats["filled"] - before + int(part.stats["filled"])
        f.stats.update(filled=filled, visits=part.stats["visits"])
        f.stats["overdraw"] = float(part.stats["visits"] / part.stats["filled"]) if part.stats["filled"] else 0.0


def _at_moved_joints(own: Ownership, matrices: np.ndarray, moved: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """Whether each posed ball lies where a moved bone's proximal joint is posed (drawn for another bone there)."""
    if not len(centres):
        return np.zeros(0, bool)
    joints = np.array([own.bones[b].proximal @ matrices[b, :3, :3] + matrices[b, 3, :3] for b in moved])
    return (np.abs(centres[:, None, :] - joints[None]).max(2) < 1e-6).any(1)


def _clipped(own: Ownership, matrices: np.ndarray, bounds: Bounds) -> int:
    """The bones whose posed box leaves the grid (``reconstruct_owned``'s ``clipped`` for the whole frame)."""
    boxes = posed_boxes(own, matrices)
    has = boxes[:, 3] >= boxes[:, 0]
    return int((has & ((boxes[:, :3] < bounds.lo).any(1) | (boxes[:, 3:] > np.asarray(bounds.hi)).any(1))).sum())
