"""Connectivity in the studio: which bone each skeleton point is attached to.

    doc.attachments.bone[i]   bone index of skeleton point i, -1 = unconnected

Edits are undoable diffs (indices, old values, new value), so an edit of a
200 k-point cloud stores only what changed. Bone edits that renumber bones
(remove, reorder) remap this array inside the same undo step (Document).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from volanim_core import io
from volanim_core.rig import symmetry
from volanim_core.rig.attach import UNATTACHED, auto_connect
from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.connectivity import BoneSegment, Connectivity
from volanim_core.rig.skinning import Joints
from volanim_core.skeleton.points import KEY_REACH, Skeleton, voxel_keys

from .undo import Command

#: Auto-connect methods that decide every point from the whole rig (its fitted tubes): they take every shown
#: point and may replace attachments, whatever Points and Overwrite say (a selection stays a selection).
WHOLE_BODY_METHODS = ("fitted",)
MATCH_TOLERANCE = 1e-3  # voxels: Root: joints must match the bone skeleton's to this


def connectivity(skeleton: Skeleton, bones: BoneSkeleton, attached: np.ndarray, joints: Joints,
                 thinness: float | None = None) -> Connectivity:
    """The attached points of ``skeleton`` (``attached[i]``: point i's bone, -1 none) as a connectivity of
    ``bones``: a function of its arguments alone, so an autosave can make it on its own thread from a
    snapshot."""
    keep = attached >= 0
    roots = [BoneSegment(*bones.segment(i), b.label) for i, b in enumerate(bones.bones)]
    conn = Connectivity(roots, skeleton.points[keep], skeleton.dt[keep], skeleton.thinness[keep], attached[keep],
                        skeleton.metric, thinness, skeleton.geometry, joints)
    return conn.grouped()


def joints_of(settings) -> Joints:
    """How bones meet, as the settings say (rigid, or smooth with a blend width)."""
    return Joints(settings.joints, settings.blend)


class Attachments:
    def __init__(self, doc):
        self.doc = doc
        self.bone = np.zeros(0, np.int32)

    def reset(self, n: int) -> None:
        self.bone = np.full(n, UNATTACHED, np.int32)
        self.doc.events.attachments.emit(indices=None)

    # ------------------------------------------------------------------ edits
    def _write(self, indices: np.ndarray, values: np.ndarray) -> None:
        self.bone[indices] = values
        self.doc.events.attachments.emit(indices=indices)

    def assign(self, indices, bone: int, label: str | None = None) -> int:
        """Attach points to ``bone`` (-1 detaches). One undo step; returns how many changed."""
        indices = np.asarray(indices, np.int64)
        if bone != UNATTACHED and not 0 <= bone < len(self.doc.bones):
            raise ValueError(f"no bone {bone}")
        changed = indices[self.bone[indices] != bone]
        if not len(changed):
            return 0
        old = self.bone[changed].copy()
        new = np.full(len(changed), bone, np.int32)
        name = "unconnected" if bone == UNATTACHED else self.doc.bones.bones[bone].label
        label = label or f"{'Detach' if bone == UNATTACHED else 'Connect'} {len(changed)} points ({name})"
        self.doc.undo.push(Command(label, lambda: self._write(changed, new), lambda: self._write(changed, old)))
        return len(changed)

    def assign_many(self, indices, bones, label: str) -> int:
        """Set each point's bone (per-point values). One undo step."""
        indices = np.asarray(indices, np.int64)
        bones = np.asarray(bones, np.int32)
        diff = self.bone[indices] != bones
        changed, new = indices[diff], bones[diff]
        if not len(changed):
            return 0
        old = self.bone[changed].copy()
        self.doc.undo.push(Command(label, lambda: self._write(changed, new), lambda: self._write(changed, old)))
        return len(changed)

    def remapped(self, remap: np.ndarray) -> np.ndarray:
        """The array after bones are renumbered: ``remap[old] = new`` (or -1)."""
        out = self.bone.copy()
        attached = out >= 0
        out[attached] = remap[out[attached]]
        return out

    # ------------------------------------------------------------- queries
    def counts(self) -> tuple[np.ndarray, int]:
        """Points attached per bone (all points), and unconnected points among those shown."""
        b = self.bone
        per_bone = np.bincount(b[b >= 0], minlength=len(self.doc.bones))[: len(self.doc.bones)]
        n = self.doc.visible_count
        return per_bone, int((b[:n] < 0).sum())

    def label_of(self, index: int) -> str | None:
        b = int(self.bone[index]) if index < len(self.bone) else UNATTACHED
        return None if b < 0 else self.doc.bones.bones[b].label

    # ------------------------------------------------------- auto and mirror
    def auto(self, *, scope: str = "unconnected", overwrite: bool = False, selection=None, method: str = "path"):
        """Auto-connect shown points: scope 'all', 'unconnected' or 'selection'. Returns the report."""
        task, apply = self.auto_job(scope=scope, overwrite=overwrite, selection=selection, method=method)
        return apply(task())

    def auto_job(self, *, scope: str = "unconnected", overwrite: bool = False, selection=None,
                 method: str = "path"):
        """Auto-connect as ``(task, apply)`` for a worker: ``task(progress, cancel)`` measures on the
        document's arrays as they are now and changes nothing (safe off the GUI thread: the pieces
        method takes seconds on a frog); ``apply(result)`` assigns its attachments as one undo step and
        returns the report. Bad arguments raise ValueError here, before any work."""
        doc = self.doc
        if doc.mask is None:
            raise ValueError("auto-connect needs the segmented volume: open the volume (or project) first")
        n = doc.visible_count
        which = np.zeros(len(self.bone), bool)
        if method in WHOLE_BODY_METHODS and scope != "selection":
            # it decides each point from the whole rig's tubes, so it is asked of every shown point (#83:
            # chosen alone, with the default "unconnected" points, it attached 0 of a connected body)
            scope, overwrite = "all", True
        if scope == "selection":
            if selection is None or not len(selection):
                raise ValueError("select points with the cube or lasso first")
            which[np.asarray(selection)] = True
        elif scope in ("all", "unconnected"):
            which[:n] = True
            overwrite = overwrite if scope == "all" else False
        else:
            raise ValueError(f"scope must be 'all', 'unconnected' or 'selection', got {scope!r}")
        points, dt, bones, mask, current = doc.skeleton.points, doc.skeleton.dt, doc.bones, doc.mask, self.bone.copy()

        def task(progress=None, cancel=None):
            return auto_connect(points, bones, mask, method=method, current=current, overwrite=overwrite,
                                which=which, radii=dt, progress=progress, cancel=cancel)

        def apply(result):
            out, report = result
            if doc.skeleton is None or doc.skeleton.points is not points or doc.bones is not bones:
                raise ValueError("the skeleton or the bones changed while auto-connect ran: run it again")
            idx = np.flatnonzero(which & (out != self.bone))
            self.assign_many(idx, out[idx], f"Auto-connect {len(idx)} points")
            return report

        return task, apply

    def mirror(self, bones=None) -> tuple[int, int]:
        """Copy the attachments of sided bones to their twins across the symmetry plane.

        Each point on bone ``L_X`` is mirrored across ``x = symmetry_x`` and the
        nearest skeleton point within 1.5 voxels goes to the twin bone. Returns
        ``(points copied, points with no partner)``. One undo step.
        """
        doc = self.doc
        bones = doc.selected_bones if bones is None else bones
        if not bones:
            raise ValueError("select the bones whose connectivity to mirror")
        idx, vals, lonely = symmetry.mirrored_attachments(doc.skeleton.points, self.bone, doc.bones, bones,
                                                          doc.symmetry_x)
        copied = self.assign_many(idx, vals, f"Mirror connectivity of {len(bones)} bone(s)")
        return copied, lonely

    # ----------------------------------------------------------------- files
    def to_connectivity(self, thinness: float | None = None) -> Connectivity:
        doc = self.doc
        s = doc.skeleton
        if s is None:  # an empty studio: F5, exports and saves end here, with words instead of a traceback
            raise ValueError("nothing loaded yet: open a volume, a demo or a project first (File menu)")
        return connectivity(s, doc.bones, self.bone, joints_of(doc.settings), thinness)

    def save(self, path, thinness: float | None = None) -> int:
        """Write attached points with thinness >= ``thinness`` (default: the slider) atomically."""
        t = self.doc.thinness if thinness is None else thinness
        conn = self.to_connectivity(t)
        io.write_connect(path, conn, thinness=t)
        return int((conn.thinness >= t).sum())

    def default_filename(self, stem: str) -> str:
        return io.connect_filename(stem, self.doc.thinness)

    def load(self, path) -> list[str]:
        """Reload a ``.connect`` onto the loaded skeleton (or alone); returns warnings.

        Points match by integer coordinates; points the cloud lacks are added
        (never dropped). Its bones must be the loaded bone skeleton's, in any
        order (matched by joint coordinates); with no bones loaded, the file's
        become the bone skeleton. A load, not an edit: the history starts after it.
        """
        conn = io.read_connect(path)
        warnings = self.doc.loading(lambda: self.apply_connectivity(conn, Path(path).name))
        if conn.joints.smooth:  # the file's joints become the Reconstruct tab's
            self.doc.settings.joints = "smooth"
            if conn.joints.mm:
                warnings.append(f"{Path(path).name}: smooth joints {conn.joints.text()}: the studio sets the "
                                f"blend as a multiple of the bones' thickness, kept at {self.doc.settings.blend:g}")
            else:
                self.doc.settings.blend = min(max(conn.joints.blend, 0.1), 10.0)
        return warnings

    def apply_connectivity(self, conn, name: str) -> list[str]:
        """:meth:`load` for a connectivity already read (``name`` is its file's, for messages)."""
        doc = self.doc
        warnings: list[str] = []
        remap = self._match_bones(conn, name)
        if doc.skeleton is None or not len(doc.skeleton):
            th = conn.thinness if not np.isnan(conn.thinness).all() else np.zeros(len(conn))
            doc.set_skeleton(Skeleton(conn.points, conn.dt, np.nan_to_num(th), conn.metric, conn.geometry),
                             path=None)
        s = doc.skeleton
        found = row_positions(s.points, conn.points)
        missing = found < 0
        if missing.any():
            warnings.append(f"{name}: {int(missing.sum())} points are not in the loaded skeleton; "
                            "they were added to it")
            fill = conn.thinness_threshold if conn.thinness_threshold is not None else 0.0
            th = np.where(np.isnan(conn.thinness[missing]), fill, conn.thinness[missing])
            merged = Skeleton(np.vstack([s.points, conn.points[missing]]), np.r_[s.dt, conn.dt[missing]],
                              np.r_[s.thinness, th], s.metric, s.geometry)
            old_bone = np.r_[self.bone, np.full(int(missing.sum()), UNATTACHED, np.int32)]
            order = np.argsort(-merged.thinness, kind="stable")
            doc.set_skeleton(Skeleton(merged.points[order], merged.dt[order], merged.thinness[order], s.metric,
                                      s.geometry),
                             path=doc.mskel_path, keep_attachments=old_bone[order])
            doc.undo.clear()  # the cloud changed under the history
            s = doc.skeleton
            found = row_positions(s.points, conn.points)
        self.assign_many(found, remap[conn.bone], f"Load {name}")
        return warnings

    def _match_bones(self, conn: Connectivity, name: str) -> np.ndarray:
        """``remap[file bone] = document bone``; adopts the file's bones when none are loaded."""
        doc = self.doc
        if not len(doc.bones):
            joints: dict = {}
            bones = []

            def joint_for(xyz):
                for k, v in joints.items():
                    if np.allclose(v, xyz, atol=MATCH_TOLERANCE):
                        return k
                k = f"J{len(joints) + 1}"
                joints[k] = np.asarray(xyz, np.float64)
                return k

            for r in conn.bones:
                bones.append(Bone(joint_for(r.proximal), joint_for(r.distal), r.name))
            doc.bone_edits.set_bones(BoneSkeleton(joints, bones), f"Bones from {name}")
            return np.arange(len(conn.bones), dtype=np.int32)
        segs = doc.bones.segments()
        remap = np.empty(len(conn.bones), np.int32)
        for i, r in enumerate(conn.bones):
            hit = np.flatnonzero(np.abs(segs[:, 0] - r.proximal).max(1) <= MATCH_TOLERANCE)
            hit = [h for h in hit if np.abs(segs[h, 1] - r.distal).max() <= MATCH_TOLERANCE]
            if not hit:
                raise ValueError(f"{name}: bone {i} ({r.label}) is not in the loaded bone skeleton -- the file was "
                                 "made for a different bone skeleton; open its .bones first")
            remap[i] = hit[0]
        return remap


def row_positions(rows: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Where each row (x, y, z) of ``wanted`` is in ``rows`` (-1: not there), by exact value; ``rows``
    distinct (a skeleton's points). Voxel points, whole numbers, go by one integer key each
    (:func:`~volanim_core.skeleton.points.voxel_keys`), sorted: a dict of tuples took 55 ms of
    mannequin-large's project open on the GUI thread."""
    rows, wanted = np.asarray(rows, np.float64), np.asarray(wanted, np.float64)
    if not len(rows) or not len(wanted) or not (_keyable(rows) and _keyable(wanted)):
        index = {tuple(p): i for i, p in enumerate(rows.tolist())}
        return np.array([index.get(tuple(p), -1) for p in wanted.tolist()], np.int64)
    a, b = voxel_keys(rows), voxel_keys(wanted)
    order = np.argsort(a)
    at = np.minimum(np.searchsorted(a[order], b), len(a) - 1)
    return np.where(a[order][at] == b, order[at], -1).astype(np.int64)


def _keyable(points: np.ndarray) -> bool:
    return bool(np.abs(points).max() < KEY_REACH and (points == np.round(points)).all())
