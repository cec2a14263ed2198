"""The pose being previewed: per-bone rotations (and shifts) driving FK.

Keyed by the bone's joint names, not its index, so reordering bones keeps the
pose. Slider drags merge into one undo step (``UndoStack`` merge keys).

    angles[(proximal, distal)] = (rx, ry, rz) degrees about the proximal joint
    matrices() -> volanim_core.rig.pose.pose_matrices -> (B, 4, 4)
"""

from __future__ import annotations

import numpy as np

from volanim_core import io
from volanim_core.rig.connectivity import Trans, Tskel
from volanim_core.rig.pose import local_motion, pose_matrices, posed_joints, root_bones
from volanim_core.rig.tskel_tools import check_root_order

from .undo import Command


class PoseState:
    def __init__(self, doc):
        self.doc = doc
        self.angles: dict[tuple[str, str], np.ndarray] = {}
        self.shifts: dict[tuple[str, str], np.ndarray] = {}
        self._rest_parts = None  # (key, breakage.RestParts) of the current attachments
        self.rest_version = 0  # counts attachment changes: a report made before one must not be kept
        self._rest_preview = None  # (key, Preview) of the rest pose, for Compare (settings.show_rest)
        self._frame_conn = None  # (what it was made of, the connectivity): frame_maker's, kept between pictures
        doc.events.attachments.connect(self._forget_rest_parts)
        doc.events.bones.connect(self._forget_rest_parts)

    def _forget_rest_parts(self, **_) -> None:
        self._rest_parts = None
        self._rest_preview = None
        self.rest_version += 1

    def rest_preview(self, mode: str):
        """The rest pose's reconstruction in ``mode`` (Compare shows it instead of the posed one), made
        once per attachments, bones, thinness and mode; None when nothing is attached."""
        from volanim_core.rig.tskel_tools import identity_tskel

        from .preview import make_preview

        key = (self.rest_version, self.doc.thinness, mode, self.doc.settings.body, self.doc.ownership.version)
        if self._rest_preview is None or self._rest_preview[0] != key:
            tskel = self.tskel()
            if not len(tskel):
                return None
            rest = self.doc.ownership.attach(identity_tskel(tskel.connectivity))  # owned: the ownership itself
            self._rest_preview = (key, make_preview(rest, mode=mode, source=self.doc.volume))
        return self._rest_preview[1]

    def _rest_key(self, tskel: Tskel) -> tuple:
        # smooth joints label the rest voxels by blend; the owned body's rest is its ownership, repaints and all
        return (self.doc.thinness, len(tskel), tskel.joints, self.doc.settings.body, self.doc.ownership.version)

    def rest_parts(self, tskel: Tskel):
        """The kept :class:`~volanim_core.reconstruct.breakage.RestParts` of this frame's attachments, or None."""
        if self._rest_parts is not None and self._rest_parts[0] == self._rest_key(tskel):
            return self._rest_parts[1]
        return None

    def keep_rest_parts(self, tskel: Tskel, parts, version: int) -> None:
        """Keep a finished report's rest parts, unless the attachments changed since it was asked for
        (``version`` is :attr:`rest_version` then): a worker's result may arrive after an edit."""
        if parts is not None and version == self.rest_version:
            self._rest_parts = (self._rest_key(tskel), parts)

    def _key(self, bone: int) -> tuple[str, str]:
        b = self.doc.bones.bones[bone]
        return (b.proximal, b.distal)

    def angles_of(self, bone: int) -> np.ndarray:
        return self.angles.get(self._key(bone), np.zeros(3)).copy()

    @property
    def is_rest(self) -> bool:
        return not any(np.any(v) for v in self.angles.values()) and not any(np.any(v) for v in self.shifts.values())

    def matrices(self) -> np.ndarray:
        keys = [self._key(i) for i in range(len(self.doc.bones))]
        rot = {i: self.angles[k] for i, k in enumerate(keys) if k in self.angles}
        shift = {i: self.shifts[k] for i, k in enumerate(keys) if k in self.shifts}
        return pose_matrices(self.doc.bones, rot, shift)

    def posed_joints(self) -> dict[str, np.ndarray]:
        return posed_joints(self.doc.bones, self.matrices())

    # ----------------------------------------------------------------- edits
    def _write(self, angles: dict, shifts: dict) -> None:
        self.angles = {k: np.array(v) for k, v in angles.items()}
        self.shifts = {k: np.array(v) for k, v in shifts.items()}
        self.doc.events.pose.emit()

    def _push(self, label: str, angles: dict, shifts: dict, merge_key: str | None = None) -> None:
        old = ({k: v.copy() for k, v in self.angles.items()}, {k: v.copy() for k, v in self.shifts.items()})
        new = ({k: np.array(v) for k, v in angles.items()}, {k: np.array(v) for k, v in shifts.items()})
        timeline, looks = self.doc.timeline, self.doc.timeline.looks

        def undo():
            """What replaying the session without this edit shows: the pose before it, unless an animation's
            frame was shown since (scrubbing puts the frame's pose on the bones; so would the replay)."""
            if timeline.active and timeline.looks != looks:
                timeline.show_frame()
            else:
                self._write(*old)

        self.doc.undo.push(Command(label, lambda: self._write(*new), undo, merge_key))

    def set_angles(self, bone: int, angles, *, merge: bool = True) -> None:
        """Rotate ``bone`` about its proximal joint (x, y, z degrees); children follow."""
        angles = np.asarray(angles, np.float64).reshape(3)
        if not np.isfinite(angles).all():
            raise ValueError(f"angles must be finite numbers, got {angles}")
        new = dict(self.angles)
        new[self._key(bone)] = angles
        label = f"Pose {self.doc.bones.bones[bone].label}"
        self._push(label, new, self.shifts, merge_key=f"pose:{self._key(bone)}" if merge else None)

    def reset(self, bone: int | None = None) -> None:
        """Reset one bone (or, with None, the whole pose) to rest."""
        if bone is None:
            self._push("Reset pose", {}, {})
            return
        k = self._key(bone)
        self._push(f"Reset {self.doc.bones.bones[bone].label}", {a: v for a, v in self.angles.items() if a != k},
                   {a: v for a, v in self.shifts.items() if a != k})

    def settle(self) -> None:
        """A pose edit is finished (a typed angle, a reset): it ends its undo step and
        ``doc.events.pose_settled`` asks for the full preview. A held slider settles by its release
        (``settings.dragging`` back to False)."""
        self.doc.undo.seal()
        self.doc.events.pose_settled.emit()

    def show(self, matrices: np.ndarray) -> None:
        """Take a frame's matrices as the pose without an undo step (the timeline's current frame:
        scrubbing is looking, not editing); the sliders show the frame's angles."""
        self._write(*self._from_matrices(matrices))

    def _from_matrices(self, matrices) -> tuple[dict, dict]:
        """Slider angles and shifts (by bone key, rest entries left out) that make ``matrices``."""
        angles, shifts = local_motion(self.doc.bones, matrices)
        keys = [self._key(i) for i in range(len(self.doc.bones))]
        return ({keys[i]: a for i, a in angles.items() if np.any(np.abs(a) > 1e-9)},
                {keys[i]: t for i, t in shifts.items() if np.any(np.abs(t) > 1e-9)})

    # ----------------------------------------------------------------- state
    def to_json(self) -> dict:
        """The pose as a project holds it: ``{"angles": [[PROXIMAL, DISTAL, rx, ry, rz], ...], "shifts": [...]}``
        (joint names: the pose stays with its bones whatever order they are in). Entries of bones that
        are gone (removed, until an undo brings them back) move nothing and are not saved."""
        known = {self._key(i) for i in range(len(self.doc.bones))}

        def rows(table):
            return [[p, d, *(float(v) for v in value)] for (p, d), value in sorted(table.items()) if (p, d) in known]

        return {"angles": rows(self.angles), "shifts": rows(self.shifts)}

    @staticmethod
    def parse(data, where: str) -> tuple[dict, dict]:
        """``(angles, shifts)`` from :meth:`to_json`'s form; ValueError naming ``where`` and the bad row."""
        if not isinstance(data, dict):
            raise ValueError(f"{where}: \"pose\" must be an object, got {type(data).__name__}")
        out = []
        for key in ("angles", "shifts"):
            table = {}
            for row in data.get(key) or []:
                if not (isinstance(row, list) and len(row) == 5 and all(isinstance(v, str) for v in row[:2])
                        and all(isinstance(v, int | float) and not isinstance(v, bool) and np.isfinite(v)
                                for v in row[2:])):
                    raise ValueError(f"{where}: \"pose\" \"{key}\": expected [PROXIMAL, DISTAL, x, y, z] with "
                                     f"finite numbers, got {row!r}")
                table[(row[0], row[1])] = np.array(row[2:], np.float64)
            out.append(table)
        return out[0], out[1]

    def restore(self, angles: dict, shifts: dict) -> list[str]:
        """Take a saved pose (not an edit: no undo step); entries for bones that no longer exist are
        dropped and said."""
        known = {self._key(i) for i in range(len(self.doc.bones))}
        gone = sorted({f"{p}-{d}" for p, d in [*angles, *shifts] if (p, d) not in known})
        self._write({k: v for k, v in angles.items() if k in known}, {k: v for k, v in shifts.items() if k in known})
        return [f"the saved pose of {', '.join(gone)} was dropped: no such bone"] if gone else []

    # ----------------------------------------------------------------- files
    def load_trans(self, path) -> None:
        """Take a ``.trans`` frame as the pose (its bones must be the loaded ones, in root order); a load,
        not an edit: the history starts after it."""
        trans = io.read_trans(path).on_grid(self.doc.bones.geometry)  # a frame posed on another grid too
        check_root_order(root_bones(self.doc.bones), trans.bones, ".trans", "project's .bones")
        self.doc.loading(lambda: self._write(*self._from_matrices(trans.matrices)))

    def save_trans(self, path) -> None:
        io.write_trans(path, Trans(root_bones(self.doc.bones), self.matrices(), self.doc.bones.geometry))

    def tskel(self, thinness: float | None = None) -> Tskel:
        """The posed frame of the attached points with thinness >= ``thinness`` (default: the slider)."""
        return self.frame_maker(thinness)()

    def frame_maker(self, thinness: float | None = None):
        """:meth:`tskel` as a function of what it reads, copied now: call it on any thread. The live thread makes
        each drag's frame itself (#85: grouping the frog's 400 k attached points by bone took the GUI thread
        10-15 ms a picture); what is copied here is the attachments array and the matrices."""
        from .attachments import connectivity, joints_of

        doc = self.doc
        if doc.skeleton is None:  # an empty studio: F5, exports and saves end here, with words instead of a traceback
            raise ValueError("nothing loaded yet: open a volume, a demo or a project first (File menu)")
        skeleton, bones, attached = doc.skeleton, doc.bones, doc.attachments.bone.copy()
        joints, matrices = joints_of(doc.settings), self.matrices()
        t = doc.thinness if thinness is None else thinness

        def make() -> Tskel:
            # the same attachments as the last picture's (a drag): the same connectivity, not grouped again (the
            # frog's 400 k points: 40-90 ms a picture), and the same object, so its ownership is found at once
            of = (skeleton, bones.segments(), tuple(b.label for b in bones.bones), joints, t, attached)
            kept = self._frame_conn
            if kept is not None and _same(kept[0], of):
                return kept[1].posed(matrices)
            conn = connectivity(skeleton, bones, attached, joints)
            conn = conn.take(np.flatnonzero(~(conn.thinness < t)))
            self._frame_conn = (of, conn)
            return conn.posed(matrices)
        return make

    def posed_box(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The voxel box the posed spheres of every attached point fill (None: nothing attached): where the
        posed body is, known at once, before any preview of it is drawn."""
        from volanim_core.reconstruct.engine import posed_centres

        try:
            t = self.tskel(thinness=0.0)
        except ValueError:  # nothing loaded
            return None
        if not len(t):
            return None
        c, r = posed_centres(t), t.dt[:, None]
        return (c - r).min(0), (c + r).max(0)

    def save_tskel(self, path) -> int:
        t = self.tskel()
        io.write_tskel(path, t)
        return len(t)


def _same(a: tuple, b: tuple) -> bool:
    """Whether two frames are made of the same things: the skeleton itself, the rest by value."""
    return a[0] is b[0] and np.array_equal(a[1], b[1]) and a[2:5] == b[2:5] and np.array_equal(a[5], b[5])
