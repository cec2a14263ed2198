"""Edits of the bone skeleton: each one undoable step, attachments following renumbered bones.

    doc.bone_edits.add_bone(a, b)     doc.bone_edits.rename_joint(old, new)
    doc.bone_edits.remove_bones(ids)  doc.bone_edits.set_root_order(order)   ...
        --> one Command on doc.undo --> doc.bones replaced --> doc.events.bones

A sub-model handed the document (it owns no state but the joint counter): the
document holds the bones, this module knows how to change them. Edits are
snapshot commands: a bone skeleton is small, so a copy per edit is simpler and
safer than hand-written inverse operations.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

from volanim_core import io
from volanim_core.rig import symmetry
from volanim_core.rig.bones import Bone, BoneSkeleton

from .undo import Command

SNAP_DISTANCE = 0.5  # voxels: a click this close to a joint reuses it


def followed_selection(old: BoneSkeleton, new: BoneSkeleton, selected) -> tuple[int, ...]:
    """The rows in ``new`` of the bones selected (rows ``selected``) in ``old``: a bone is who it is, not
    the row it was in (#61: after a reorder or *Open connections…* the working bone kept its row and
    silently became another bone, and the next connect attached points to it).

    A bone is found by its joints' names (proximal, distal), or, when those are gone, by their places (a
    rename of joints, a named chain, and their undo, keep every joint where it was). A selected bone that
    is not in ``new`` leaves the selection.
    """
    rows = {(b.proximal, b.distal): i for i, b in enumerate(new.bones)}
    places = {}
    for i, b in enumerate(new.bones):
        places.setdefault(_place(new, b), i)
    out = []
    for i in selected:
        if 0 <= i < len(old.bones):
            b = old.bones[i]
            row = rows.get((b.proximal, b.distal), places.get(_place(old, b)))
            if row is not None and row not in out:
                out.append(row)
    return tuple(out)  # in the old order: the working bone (the first) stays the first


def _place(skeleton: BoneSkeleton, bone: Bone) -> tuple:
    """Where a bone's joints are (rounded), or its joint names when the skeleton lacks one."""
    if bone.proximal not in skeleton.joints or bone.distal not in skeleton.joints:
        return (bone.proximal, bone.distal)
    return tuple(tuple(np.round(np.asarray(skeleton.joints[j], np.float64), 6).tolist())
                 for j in (bone.proximal, bone.distal))


class BoneEdits:
    """Undoable edits of ``doc.bones``."""

    def __init__(self, doc):
        self.doc = doc
        self._joint_counter = 0

    def _apply_bones(self, label: str, new: BoneSkeleton, remap: np.ndarray | None = None) -> None:
        """One undo step: the new bone skeleton and, when bones are renumbered
        (``remap[old index] = new index`` or -1), the attachments that follow."""
        old = copy.deepcopy(self.doc.bones)
        new = copy.deepcopy(new)
        new.validate()
        changed = old_vals = new_vals = None
        if remap is not None and len(self.doc.attachments.bone):
            after = self.doc.attachments.remapped(np.asarray(remap, np.int32))
            changed = np.flatnonzero(after != self.doc.attachments.bone)
            old_vals, new_vals = self.doc.attachments.bone[changed].copy(), after[changed]

        def redo():
            self._set_bones(copy.deepcopy(new))
            if changed is not None and len(changed):
                self.doc.attachments._write(changed, new_vals)

        def undo():
            self._set_bones(copy.deepcopy(old))
            if changed is not None and len(changed):
                self.doc.attachments._write(changed, old_vals)

        self.doc.undo.push(Command(label, redo, undo))

    def _set_bones(self, bones: BoneSkeleton) -> None:
        self.doc.selected_bones = followed_selection(self.doc.bones, bones, self.doc.selected_bones)
        self.doc.bones = bones
        if self.doc.picked_joint not in bones.joints:
            self.doc.picked_joint = None  # renamed or removed (an undo of a rename)
        self.doc.events.bones.emit()
        self.doc.events.selection.emit(indices=self.doc.selected_bones)

    def _edited(self) -> BoneSkeleton:
        return copy.deepcopy(self.doc.bones)

    def joint_at(self, position, tolerance: float = SNAP_DISTANCE) -> str | None:
        """The joint within ``tolerance`` voxels of ``position``, if any."""
        best, name = tolerance, None
        for n, xyz in self.doc.bones.joints.items():
            d = float(np.linalg.norm(xyz - np.asarray(position, float)))
            if d <= best:
                best, name = d, n
        return name

    def default_joint_name(self, position) -> str:
        """``L_J7`` / ``R_J7`` / ``J7`` by the side of the symmetry plane: the UI nudges towards L_/R_."""
        while True:
            self._joint_counter += 1
            x = float(position[0])
            prefix = "" if abs(x - self.doc.symmetry_x) < 1.0 else ("L_" if x > self.doc.symmetry_x else "R_")
            name = f"{prefix}J{self._joint_counter}"
            if name not in self.doc.bones.joints:
                return name

    def add_bone(self, a, b, name: str = "") -> int:
        """A bone from joint/position ``a`` to joint/position ``b``; returns its index.

        ``a``/``b`` are joint names or positions; a position reuses a joint
        within :data:`SNAP_DISTANCE` or creates a new one. One undo step.
        """
        new = self._edited()
        names = []
        for end in (a, b):
            if isinstance(end, str):
                if end not in new.joints:
                    raise ValueError(f"no joint named {end!r}")
                names.append(end)
                continue
            found = self.joint_at(end)
            if found is None:
                found = next((n for n, xyz in new.joints.items() if np.allclose(xyz, end)), None)
            if found is None:
                found = self.default_joint_name(end)
                new.joints[found] = np.asarray(end, np.float64)
            names.append(found)
        if names[0] == names[1]:
            raise ValueError("a bone needs two different joints")
        if any({x.proximal, x.distal} == set(names) for x in new.bones):
            raise ValueError(f"there is already a bone between {names[0]} and {names[1]}")
        new.bones.append(Bone(names[0], names[1], name))
        self._apply_bones(f"Add bone {names[0]}-{names[1]}", new)
        return len(self.doc.bones) - 1

    def remove_bones(self, indices) -> None:
        """Remove bones; joints no bone uses any more go too. One undo step."""
        indices = set(int(i) for i in indices)
        if not indices:
            return
        new = self._edited()
        new.bones = [b for i, b in enumerate(new.bones) if i not in indices]
        used = {j for b in new.bones for j in (b.proximal, b.distal)}
        new.joints = {k: v for k, v in new.joints.items() if k in used}
        remap = np.full(len(self.doc.bones), -1, np.int32)
        kept = [i for i in range(len(self.doc.bones)) if i not in indices]
        remap[kept] = np.arange(len(kept))
        self.doc.selected_bones = ()
        self._apply_bones(f"Remove {len(indices)} bone(s)", new, remap)

    def rename_joint(self, old: str, new_name: str) -> None:
        new_name = new_name.strip()
        if not new_name or any(c.isspace() for c in new_name):
            raise ValueError(f"joint names cannot be empty or contain spaces: {new_name!r}")
        if old == new_name:
            return
        if new_name in self.doc.bones.joints:
            raise ValueError(f"there is already a joint named {new_name!r}")
        new = self._edited()
        new.joints = {(new_name if k == old else k): v for k, v in new.joints.items()}
        new.bones = [Bone(new_name if b.proximal == old else b.proximal, new_name if b.distal == old else b.distal,
                          b.name) for b in new.bones]
        picked = self.doc.picked_joint == old
        self._apply_bones(f"Rename joint {old} to {new_name}", new)
        if picked:  # the renamed joint stays the picked one
            self.doc.pick_joint(new_name)

    def chain_from(self, joint: str) -> list[str]:
        """The joints of the chain that starts at ``joint``: follow the one bone leaving each joint
        until a joint has no bone or several (a fork: the neck, the pelvis)."""
        if joint not in self.doc.bones.joints:
            raise ValueError(f"no joint named {joint!r}")
        chain = [joint]
        while True:
            out = [b.distal for b in self.doc.bones.bones if b.proximal == chain[-1]]
            if len(out) != 1 or out[0] in chain:
                return chain
            chain.append(out[0])

    def chain_through(self, bone: int) -> list[str]:
        """The joints of the unbranched chain that holds ``bone``, from its top: up while a joint has one
        bone in and one out, down while it has one out. A fork ends it and is included (the neck
        starts an arm's chain: NECK, L_SHOULDER, L_ELBOW, L_WRIST, L_FINGERS)."""
        bones = self.doc.bones.bones
        leaving = {j: [b.distal for b in bones if b.proximal == j] for j in self.doc.bones.joints}
        entering = {j: [b.proximal for b in bones if b.distal == j] for j in self.doc.bones.joints}
        chain = [bones[bone].proximal, bones[bone].distal]
        while len(entering[chain[0]]) == 1 and len(leaving[chain[0]]) == 1 and entering[chain[0]][0] not in chain:
            chain.insert(0, entering[chain[0]][0])
        while len(leaving[chain[-1]]) == 1 and leaving[chain[-1]][0] not in chain:
            chain.append(leaving[chain[-1]][0])
        return chain

    def side_prefix(self, joint: str) -> str:
        """``L_`` or ``R_`` by the joint's side of the symmetry plane (the figure's left is +x), ``""`` near
        it: within 5 % of the volume's width (a click at the pelvis lands a few voxels off the middle)."""
        shape = self.doc.shape
        tolerance = max(2.0, 0.05 * shape[0]) if shape else 2.0
        dx = float(self.doc.bones.joints[joint][0]) - self.doc.symmetry_x
        return "" if abs(dx) <= tolerance else ("L_" if dx > 0 else "R_")

    def is_fork(self, joint: str) -> bool:
        """Whether ``joint`` joins more than one chain (more than two bones meet there)."""
        return sum((b.proximal == joint) + (b.distal == joint) for b in self.doc.bones.bones) > 2

    def joints_named(self, chain: list[str], count: int) -> list[str]:
        """The joints of ``chain`` that ``count`` typed names go to, in order: all of them when ``count``
        covers the chain, else the chain's own joints after a fork at its top (the fork keeps its name)."""
        own = chain[1:] if count < len(chain) and len(chain) > 1 and self.is_fork(chain[0]) else chain
        return own[:count]

    def rename_chain(self, chain: list[str], names, *, sided: bool = True) -> list[str]:
        """Name the joints of ``chain`` (:meth:`chain_through`, :meth:`chain_from`) in order, one undo
        step; returns the new names.

        ``names`` (a list, or one string split at commas and spaces) may be shorter than the chain
        (the rest keep their names). A chain that starts at a fork (the neck of an arm's chain)
        names the fork only when every joint gets a name: fewer names start after it, since the fork
        belongs to other chains too ("SHOULDER, ELBOW, WRIST, FINGERS" from the neck renamed the
        neck and left the fingertip unnamed, issue #37). With ``sided``, a name without
        ``L_``/``R_`` gets the side of its joint: "SHOULDER, ELBOW, WRIST" on the left arm gives
        L_SHOULDER, L_ELBOW, L_WRIST.
        """
        if isinstance(names, str):
            names = names.replace(",", " ").split()
        names = [n.strip() for n in names if n.strip()]
        if not names:
            raise ValueError("type the names of the chain's joints, e.g. SHOULDER, ELBOW, WRIST")
        if len(names) > len(chain):
            raise ValueError(f"{len(names)} names for a chain of {len(chain)} joints ({', '.join(chain)})")
        chain = self.joints_named(chain, len(names))
        if sided:  # a joint already called so keeps its name (the pelvis that starts a leg's chain)
            names = [n if n[:2] in ("L_", "R_") or n == j else self.side_prefix(j) + n for n, j in zip(names, chain)]
        mapping = {old: new for old, new in zip(chain, names) if old != new}
        if len(set(names)) != len(names):
            raise ValueError(f"a name appears twice: {', '.join(names)}")
        clash = [n for n in mapping.values() if n in self.doc.bones.joints and n not in mapping]
        if clash:
            raise ValueError(f"there is already a joint named {clash[0]!r} outside this chain")
        if not mapping:
            return names
        new = self._edited()
        new.joints = {mapping.get(k, k): v for k, v in new.joints.items()}
        new.bones = [Bone(mapping.get(b.proximal, b.proximal), mapping.get(b.distal, b.distal), b.name)
                     for b in new.bones]
        picked = mapping.get(self.doc.picked_joint)
        self._apply_bones(f"Name chain {', '.join(names)}", new)
        if picked is not None:
            self.doc.pick_joint(picked)
        return names

    def rename_bone(self, index: int, name: str) -> None:
        name = name.strip()
        if any(c.isspace() for c in name):
            raise ValueError(f"bone names cannot contain spaces: {name!r}")
        new = self._edited()
        b = new.bones[index]
        new.bones[index] = Bone(b.proximal, b.distal, name)
        self._apply_bones(f"Rename bone {b.label} to {name or '(none)'}", new)

    def move_joint(self, name: str, position) -> None:
        new = self._edited()
        new.joints[name] = np.asarray(position, np.float64)
        self._apply_bones(f"Move joint {name}", new)

    def set_root_order(self, order) -> None:
        """Reorder bones: ``order[k]`` is the old index of the new bone k."""
        order = [int(i) for i in order]
        if sorted(order) != list(range(len(self.doc.bones))):
            raise ValueError(f"root order must be a permutation of 0..{len(self.doc.bones) - 1}, got {order}")
        if order == list(range(len(self.doc.bones))):
            return
        new = self._edited()
        new.bones = [new.bones[i] for i in order]
        remap = np.empty(len(order), np.int32)
        remap[order] = np.arange(len(order))
        self._apply_bones("Reorder bones", new, remap)

    def set_bones(self, bones: BoneSkeleton, label: str = "Load bones") -> None:
        """Replace the bone skeleton; attachments follow bones with the same joints, others are cleared."""
        keys = {(b.proximal, b.distal): i for i, b in enumerate(bones.bones)}
        remap = np.array([keys.get((b.proximal, b.distal), -1) for b in self.doc.bones.bones], np.int32)
        self._apply_bones(label, bones, remap)

    def symmetrize(self, indices=None) -> list[str]:
        """Mirror bones (default: the selection) to the other side by their L_/R_ names.

        Each sided joint's twin (``L_X`` <-> ``R_X``) is created or moved to
        the mirror image across ``x = symmetry_x``, snapped to the nearest
        skeleton point; centre joints stay. Missing twin bones are added.
        Returns the names of the joints written. One undo step.
        """
        indices = self.doc.selected_bones if indices is None else tuple(indices)
        if not indices:
            raise ValueError("select the bones to mirror first")
        new = self._edited()
        pts = self.doc.skeleton.points if self.doc.skeleton is not None else None
        written = []
        for i in indices:
            b = new.bones[i]
            if symmetry.side_of(b.proximal) is None and symmetry.side_of(b.distal) is None:
                raise ValueError(f"bone {b.label} has no L_/R_ joint to mirror; rename its joints first")
            twin_ends = []
            for j in (b.proximal, b.distal):
                t = symmetry.mirror_name(j)
                if t != j:
                    new.joints[t] = symmetry.snap(pts, symmetry.mirror_point(new.joints[j], self.doc.symmetry_x))
                    if t not in written:  # a chain shares joints: each is named once
                        written.append(t)
                twin_ends.append(t)
            twin = Bone(twin_ends[0], twin_ends[1], symmetry.mirror_name(b.name) if b.name else "")
            existing = [k for k, x in enumerate(new.bones) if (x.proximal, x.distal) == tuple(twin_ends)]
            if existing:
                new.bones[existing[0]] = twin
            else:
                new.bones.append(twin)
        self._apply_bones(f"Symmetrize {len(indices)} bone(s)", new)
        return written

    # ----------------------------------------------------------------- files
    def load_bones(self, path, bones=None) -> None:
        """Load a ``.bones`` file (or ``bones`` already read from ``path``): not an undo step, the history
        starts after it (:meth:`Document.loading`)."""
        bones = io.read_bones(path) if bones is None else bones
        if self.doc.skeleton is not None:  # onto the skeleton's grid: a file's joints may be in other voxels
            bones = bones.on_grid(self.doc.skeleton.geometry)
        self.doc.loading(lambda: self.set_bones(bones, f"Load {Path(path).name}"))
        self.doc.bones_path = str(path)

    def load_connections(self, path) -> None:
        """Take the bone list (root order) from a ``.connections`` file over the loaded joints.

        Bones that stay keep their names and attachments. A load: the history starts after it.
        """
        pairs = io.read_connections(path)
        missing = sorted({j for pair in pairs for j in pair} - set(self.doc.bones.joints))
        if missing:
            raise ValueError(f"{Path(path).name} names joints that are not loaded: {', '.join(missing)}; "
                             "open the .bones file with those joints first")
        names = {(b.proximal, b.distal): b.name for b in self.doc.bones.bones}
        new = BoneSkeleton(copy.deepcopy(self.doc.bones.joints), [Bone(a, b, names.get((a, b), "")) for a, b in pairs])
        self.doc.loading(lambda: self.set_bones(new, f"Load {Path(path).name}"))

    def save_bones(self, path) -> None:
        io.write_bones(path, self.doc.bones, self.doc.grid)
        self.doc.bones_path = str(path)

    def save_connections(self, path) -> None:
        io.write_connections(path, self.doc.bones)
