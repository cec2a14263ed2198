"""The rig's ownership in the studio: which bone moves each voxel of the body, and the animator's repaints. Qt-free.

    doc.mask (the segmented volume) + the attachments (at the thinness) --rig/ownership.py, in the preview's
    worker, once per rig--> Ownership --the repaints, in order--> what full previews move (the default body)
    paint_box / paint_voxels / fix_lump --> one undo step each --> the repaints (saved as the project's
        "ownership" part: each as its bone and a box, or runs of voxel indices) --> events.ownership

Why here and not in the attachments: the thesis's points choose which spheres grow; ownership chooses which
bone each voxel of the scan follows (#84). Repaints are kept as edits on top of the made ownership, so a
changed attachment makes it again and the animator's fixes still hold where they were painted.
"""

from __future__ import annotations

import threading

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.rig.connectivity import Tskel
from volanim_core.rig.ownership import Ownership, ownership


class OwnershipState:
    def __init__(self, doc):
        self.doc = doc
        # ((bone, ("box", lo, hi) | ("voxels", flat indices, Fortran order)), ...): replaced whole, never changed
        self.paints: tuple = ()
        self._made = None  # (key, Ownership before the paints)
        self._painted_made = None  # (the Ownership before the paints, the paints, the Ownership with them)
        self._last_key = None  # (connectivity, mask, its key): the last one asked about
        self._attached = None  # (connectivity, ownership, the connectivity with it): attach's last
        self._lock = threading.Lock()  # the preview's worker makes it while the GUI thread may ask again
        self.version = 0  # counts repaints: a preview made before one is old
        self.shown: Ownership | None = None  # what the hull is coloured by (show()); None: not made for this rig
        for event in ("attachments", "bones", "volume", "skeleton", "thinness"):
            getattr(doc.events, event).connect(lambda **_: self._forget())
        doc.events.ownership.connect(lambda **_: self.show(None))

    def _forget(self) -> None:
        self._made = self._painted_made = self._last_key = self._attached = None
        self.show(None)

    def show(self, own: Ownership | None) -> None:
        """The ownership the hull shows, made for the rig as it is now (None: none yet, or the rig changed since:
        the hull shows its own colour rather than an old ownership). On the GUI thread."""
        if own is self.shown:
            return
        self.shown = own
        self.doc.events.owners_shown.emit()

    @property
    def available(self) -> bool:
        """Whether the body can be moved by ownership: a segmented volume on the skeleton's grid."""
        return self.doc.mask is not None and self.doc.skeleton is not None and len(self.doc.bones) > 0

    # ------------------------------------------------------------------ making
    def of(self, conn) -> Ownership | None:
        """The ownership of ``conn`` (the attachments at the thinness) over the document's mask, with the
        repaints; None when it cannot be made (no volume, nothing attached). Made once per rig, in the caller's
        thread: call it from a worker."""
        if not self.available or not len(conn):
            return None
        with self._lock:
            last = self._last_key
        if last is not None and last[0] is conn and last[1] is self.doc.mask:
            key = last[2]  # the same connectivity as the last picture's (a drag): not hashed again
        else:
            key = (id(self.doc.mask), len(conn), conn.points.tobytes().__hash__(), conn.bone.tobytes().__hash__(),
                   tuple(b.label for b in conn.bones))
            with self._lock:
                self._last_key = (conn, self.doc.mask, key)
        with self._lock:
            made = self._made
        if made is None or made[0] != key:
            made = (key, ownership(self.doc.mask, conn))
            with self._lock:
                self._made = made
        paints = self.paints
        with self._lock:
            painted = self._painted_made
        if painted is None or painted[0] is not made[1] or painted[1] != paints:
            # kept: every live picture of a drag asks, and each new object would start the live grid again
            painted = (made[1], paints, self._painted(made[1], paints))
            with self._lock:
                self._painted_made = painted
        return painted[2]

    def _painted(self, own: Ownership, paints) -> Ownership:
        if not paints:
            return own
        full = own.volume(self.doc.mask.shape)
        flat = full.reshape(-1, order="F")  # a view: full is Fortran-ordered
        for bone, (kind, *where) in paints:
            if bone >= len(own.bones):
                continue  # a bone removed since: its repaint has nothing to give to
            idx = _box_indices(where[0], where[1], full.shape) if kind == "box" else where[0]
            idx = idx[flat[idx] != 0]  # only the body: a repaint moves flesh, never makes it
            flat[idx] = bone + 1
        lo = np.asarray(own.origin)
        labels = np.asfortranarray(full[tuple(slice(o, o + n) for o, n in zip(lo, own.labels.shape))])
        return own.with_labels(labels)

    def attach(self, tskel: Tskel) -> Tskel:
        """``tskel`` with its rig's ownership when the preview moves the body by it (the default body, rigid
        joints, a volume loaded); as it is otherwise. Runs in the preview's worker."""
        if self.doc.settings.body != "owned" or tskel.joints.smooth:
            return tskel
        conn = tskel.connectivity
        own = self.of(conn)
        if own is None:
            return tskel
        with self._lock:
            last = self._attached
        if last is None or last[0] is not conn or last[1] is not own:  # else a drag's next picture: kept
            last = (conn, own, conn.with_ownership(own))  # (a copy of the frog's 400 k points)
            with self._lock:
                self._attached = last
        return last[2].posed(tskel.matrices)

    # ------------------------------------------------------------------ repainting
    def _set(self, paints: tuple) -> None:
        self.paints = paints
        self.version += 1
        self.doc.events.ownership.emit()

    def _push(self, label: str, *paints) -> None:
        """Repaints as one undo step."""
        from .undo import Command

        old, new = self.paints, (*self.paints, *paints)
        self.doc.undo.push(Command(label, lambda: self._set(new), lambda: self._set(old)))

    def paint_box(self, lo, hi, bone: int) -> None:
        """The body's voxels in the box ``lo..hi`` (inclusive, rest voxels) to ``bone``: one undo step."""
        self._check(bone)
        lo, hi = np.asarray(lo, int), np.asarray(hi, int)
        self._push(f"Own box by {self.doc.bones.bones[bone].label}", (bone, ("box", lo, hi)))

    def paint_voxels(self, indices, bone: int, label: str | None = None) -> None:
        """The body's voxels at flat ``indices`` (Fortran order over the volume's grid) to ``bone``."""
        self._check(bone)
        indices = np.unique(np.asarray(indices, np.int64))
        if not len(indices):
            return
        self._push(label or f"Own {len(indices)} voxels by {self.doc.bones.bones[bone].label}",
                   (bone, ("voxels", indices)))

    def flesh_of(self, points: np.ndarray) -> np.ndarray:
        """Flat indices (Fortran order over the volume's grid) of the body's voxels inside the spheres of skeleton
        points ``points`` (indices into the skeleton): the flesh those points stand for, which a lasso gives to a
        bone with them (the thesis's sphere of each point: its distance-transform radius)."""
        sk, mask = self.doc.skeleton, self.doc.mask
        if sk is None or mask is None or not len(points):
            return np.zeros(0, np.int64)
        centres = sk.points[np.asarray(points, np.int64)].astype(np.int64)
        radii = sk.dt[np.asarray(points, np.int64)] / (3.0 if sk.metric == "345" else 1.0)
        found = []
        for c, r in zip(centres, radii):
            lo = np.maximum(c - int(np.floor(r)), 0)
            hi = np.minimum(c + int(np.floor(r)), np.asarray(mask.shape) - 1)
            axes = [np.arange(a, b + 1) for a, b in zip(lo, hi)]
            x, y, z = np.meshgrid(*axes, indexing="ij")
            inside = ((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2 <= r * r) & mask[x, y, z]
            found.append(np.ravel_multi_index((x[inside], y[inside], z[inside]), mask.shape, order="F"))
        return np.unique(np.concatenate(found)) if found else np.zeros(0, np.int64)

    def _check(self, bone: int) -> None:
        if not 0 <= bone < len(self.doc.bones):
            raise ValueError(f"no bone {bone}")
        if not self.available:
            raise ValueError("ownership needs the volume: open it (File → Open volume)")

    def hang_on(self, own: Ownership) -> tuple[list, list]:
        """What *Hang stray flesh on* paints (rig/reach.hang_on): ``([(bone, flat indices over the volume's grid)],
        [(from bone, to bone, voxels)])``, flesh that touches the body only through another limb's given to the
        flesh it hangs from. Pure: made in a worker, painted by :meth:`paint_many` (one undo step)."""
        from volanim_core.rig.reach import hang_on

        hung, moved = hang_on(own)
        changed = hung.labels != own.labels
        xyz = np.argwhere(changed) + np.asarray(own.origin)
        bone = hung.labels[changed].astype(np.int64) - 1
        flat = np.ravel_multi_index(tuple(xyz.T), self.doc.mask.shape, order="F")
        return [(int(b), flat[bone == b]) for b in np.unique(bone)], moved

    def paint_many(self, paints: list, label: str) -> None:
        """Several bones' voxels (``[(bone, flat indices)]``) repainted as one undo step."""
        for bone, _ in paints:
            self._check(bone)
        kept = [(bone, ("voxels", np.unique(np.asarray(idx, np.int64)))) for bone, idx in paints if len(idx)]
        if kept:
            self._push(label, *kept)

    def fix_lump(self, own: Ownership, matrices: np.ndarray, lump, to_bone: int) -> int:
        """Give the rest voxels a lump was made of to ``to_bone``: each voxel of another bone whose posed place
        lies in the lump's box (:meth:`Ownership.carried_into`). One undo step; returns the voxels."""
        taken = own.carried_into(matrices, lump.lo, lump.hi, but=to_bone)
        if not len(taken):
            return 0
        # indices of the labels' box -> of the volume's grid, as repaints are kept
        xyz = np.column_stack(np.unravel_index(taken, own.labels.shape, order="F")) + np.asarray(own.origin)
        flat = np.ravel_multi_index(tuple(xyz.T), self.doc.mask.shape, order="F")
        near = getattr(lump, "near", "") or "the joint"
        self.paint_voxels(flat, to_bone, f"Fix lump near {near}: {len(taken)} voxels to "
                                         f"{self.doc.bones.bones[to_bone].label}")
        return len(taken)

    # ------------------------------------------------------------------ the project's part
    def to_json(self) -> list | None:
        if not self.paints:
            return None
        out = []
        for bone, (kind, *where) in self.paints:
            item = {"bone": self.doc.bones.bones[bone].label if bone < len(self.doc.bones) else int(bone)}
            if kind == "box":
                item["box"] = [int(v) for v in (*where[0], *where[1])]
            else:
                item["runs"] = _runs(where[0])
            out.append(item)
        return out

    @staticmethod
    def parse(value, path) -> list:
        if not isinstance(value, list):
            raise FormatError(path, "'ownership' must be a list of repaints")
        out = []
        for k, item in enumerate(value):
            if not isinstance(item, dict) or "bone" not in item or ("box" in item) == ("runs" in item):
                raise FormatError(path, f"ownership repaint {k}: a 'bone' and either a 'box' or 'runs'")
            if "box" in item:
                box = item["box"]
                if not (isinstance(box, list) and len(box) == 6 and all(isinstance(v, int) for v in box)):
                    raise FormatError(path, f"ownership repaint {k}: 'box' must be six integers x0 y0 z0 x1 y1 z1")
                out.append((item["bone"], ("box", np.array(box[:3]), np.array(box[3:]))))
            else:
                runs = item["runs"]
                if not (isinstance(runs, list) and all(isinstance(r, list) and len(r) == 2
                                                       and all(isinstance(v, int) and v >= 0 for v in r)
                                                       for r in runs)):
                    raise FormatError(path, f"ownership repaint {k}: 'runs' must be [start, length] pairs")
                out.append((item["bone"], ("voxels", _from_runs(runs))))
        return out

    def restore(self, parsed: list) -> list[str]:
        """Put a project's repaints back (no undo step); bones named but missing are left out, with a warning."""
        names = [b.label for b in self.doc.bones.bones]
        paints, warnings = [], []
        for bone, where in parsed:
            if isinstance(bone, str):
                if bone not in names:
                    warnings.append(f"an ownership repaint names bone {bone!r}, which the bones no longer have: "
                                    "left out")
                    continue
                bone = names.index(bone)
            paints.append((int(bone), where))
        self._set(tuple(paints))
        return warnings


def _box_indices(lo, hi, shape) -> np.ndarray:
    lo = np.maximum(np.asarray(lo, int), 0)
    hi = np.minimum(np.asarray(hi, int), np.asarray(shape) - 1)
    if (hi < lo).any():
        return np.zeros(0, np.int64)
    axes = [np.arange(a, b + 1) for a, b in zip(lo, hi)]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    return np.ravel_multi_index((x.ravel(), y.ravel(), z.ravel()), shape, order="F")


def _runs(indices: np.ndarray) -> list:
    """Sorted indices as ``[start, length]`` runs (a painted region is mostly rows of voxels)."""
    if not len(indices):
        return []
    breaks = np.flatnonzero(np.diff(indices) != 1) + 1
    starts = np.concatenate([[0], breaks])
    ends = np.concatenate([breaks, [len(indices)]])
    return [[int(indices[s]), int(e - s)] for s, e in zip(starts, ends)]


def _from_runs(runs: list) -> np.ndarray:
    if not runs:
        return np.zeros(0, np.int64)
    return np.concatenate([np.arange(s, s + n, dtype=np.int64) for s, n in runs])
