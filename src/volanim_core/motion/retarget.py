"""Retargeting a BVH clip onto our bone skeleton: per-frame bone matrices (``.trans``).

    mapping  BONE BVH_JOINT per line: the BVH joint whose world rotation drives that bone
    axes     A: BVH world axes -> ours (BVH is Y-up facing +Z; our volumes are z-up facing -y)
    rest     Q_b: the rotation taking our rest bone direction onto the clip's rest direction
    frame f  R_b(f) = A W_k(f) A^T Q_b   (W_k: the BVH joint's world rotation from its rest)

So a bone points where the clip's bone points, twist included (full rotations
are transferred, not directions: the 2001 pipeline lost twist), and a T-pose
clip drives an arms-down skeleton: the rest difference is absorbed by Q_b.
The transfer is in world space, so BVH joints between two mapped ones (Spine1,
Spine2) are absorbed. Positions come from *our* hierarchy: each bone turns
about its own proximal joint, which its parent has moved (bone lengths are
ours and never change). Unmapped bones follow their parent rigidly. The root
moves by the BVH root's displacement from the first frame, scaled by the ratio
of hip heights.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.pose import parents_first

from .bvh import Motion

AXES = {"x": 0, "y": 1, "z": 2}
OUR_UP, OUR_FORWARD = np.array([0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0])  # volanim's figures: z up, facing -y

# Suggestions: our bone name -> BVH joint names to try, in order (Mixamo and CMU share most of them).
SUGGESTIONS = {
    "SPINE": ["Spine", "LowerBack", "Spine1", "Chest"], "NECK": ["Neck", "Neck1"], "HEAD": ["Head", "Neck"],
    "PELVIS": ["Hips"], "HIPS": ["Hips"],
    "CLAVICLE": ["{S}Shoulder", "{S}Collar"], "UPPERARM": ["{S}Arm", "{S}UpArm", "{S}UpperArm"],
    "FOREARM": ["{S}ForeArm", "{S}LowArm", "{S}LowerArm"], "HAND": ["{S}Hand", "{S}Wrist"],
    "THIGH": ["{S}UpLeg", "{S}Thigh", "{S}UpperLeg"], "SHIN": ["{S}Leg", "{S}Shin", "{S}LowLeg", "{S}Knee"],
    "CALF": ["{S}Leg", "{S}Shin"], "FOOT": ["{S}Foot", "{S}Ankle"], "TOE": ["{S}ToeBase", "{S}Toe"],
}
SIDES = {"L": "Left", "R": "Right"}
ARM_PARTS = {"CLAVICLE", "SHOULDER", "UPPERARM", "ARM", "FOREARM", "ELBOW", "HAND", "WRIST"}


def _plain(name: str) -> str:
    return re.sub(r"^.*[:|]", "", name).lower()  # mixamorig:LeftArm -> leftarm


def _part(label: str) -> str:
    """``L_UPPERARM`` -> ``UPPERARM``: the body part of one of our bone labels."""
    return re.sub(r"^[LR]_", "", label.upper())


def suggest_mapping(bones: BoneSkeleton, motion: Motion) -> dict[str, str]:
    """Our bone label -> BVH joint, from common naming schemes (``L_UPPERARM`` -> ``LeftArm``).

    Pelvis bones (``L_PELVIS``, from the root joint sideways) follow the BVH root.
    """
    plain = {_plain(n): n for n in motion.names}
    out = {}
    for b in bones.bones:
        label = b.label.upper()
        m = re.fullmatch(r"(?:([LR])_)?(\w+?)", label)
        side, part = (m.group(1), m.group(2)) if m else (None, label)
        if part == "PELVIS" and side:
            out[b.label] = motion.names[0]
            continue
        for pattern in SUGGESTIONS.get(part, [part.capitalize()]):
            name = pattern.format(S=SIDES.get(side, "")).lower()
            if name in plain:
                out[b.label] = plain[name]
                break
    return out


def read_mapping(path: str | Path) -> dict[str, str]:
    """A mapping file: ``BONE BVH_JOINT`` per line, ``#`` comments."""
    from volanim_core.io._text import read_records

    rec = read_records(path)
    out: dict[str, str] = {}
    for line, toks in rec.records:
        if len(toks) != 2:
            raise rec.error(line, f"expected 'BONE BVH_JOINT', got {len(toks)} tokens")
        if toks[0] in out:
            raise rec.error(line, f"bone {toks[0]!r} is mapped twice")
        out[toks[0]] = toks[1]
    return out


def format_mapping(mapping: dict[str, str], bones: BoneSkeleton) -> str:
    lines = ["# volanim bone mapping: BONE BVH_JOINT (the BVH joint whose rotation drives the bone)"]
    lines += [f"{b.label} {mapping[b.label]}" for b in bones.bones if b.label in mapping]
    lines += [f"# {b.label} (unmapped: follows its parent)" for b in bones.bones if b.label not in mapping]
    return "\n".join(lines) + "\n"


def axes_matrix(up: str = "y", forward: str = "z") -> np.ndarray:
    """A: BVH world -> ours, from the clip's up and forward axes (``"y"``, ``"-z"``, ...)."""
    def axis(text):
        text = text.strip().lower()
        sign = -1.0 if text.startswith("-") else 1.0
        key = text.lstrip("+-")
        if key not in AXES:
            raise ValueError(f"an axis must be x, y or z (optionally signed), got {text!r}")
        v = np.zeros(3)
        v[AXES[key]] = sign
        return v

    u, f = axis(up), axis(forward)
    if abs(u @ f) > 0.5:
        raise ValueError(f"up ({up}) and forward ({forward}) must be different axes")
    source = np.column_stack([u, f, np.cross(f, u)])  # up, forward, right in BVH axes
    target = np.column_stack([OUR_UP, OUR_FORWARD, np.cross(OUR_FORWARD, OUR_UP)])
    return target @ source.T


def _align(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation taking unit direction ``a`` onto ``b``."""
    from scipy.spatial.transform import Rotation

    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    axis = np.cross(a, b)
    s, c = np.linalg.norm(axis), float(np.clip(a @ b, -1, 1))
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        other = np.eye(3)[np.argmin(np.abs(a))]  # opposite: half a turn about any perpendicular
        axis = np.cross(a, other)
        return Rotation.from_rotvec(np.pi * axis / np.linalg.norm(axis)).as_matrix()
    return Rotation.from_rotvec(axis / s * np.arctan2(s, c)).as_matrix()


def rest_directions(bones: BoneSkeleton, motion: Motion, index: dict[int, int]) -> dict[int, tuple]:
    """Per mapped bone: (our rest direction, the clip's rest direction in BVH axes), both unit vectors.

    The clip's direction points from the bone's joint towards the joints that
    drive its child bones (or its own children when none is mapped).
    """
    rest = motion.rest_positions()
    out = {}
    for b, k in index.items():
        ours = bones.joints[bones.bones[b].distal] - bones.joints[bones.bones[b].proximal]
        targets = [index[c] for c in range(len(bones)) if c in index and
                   bones.bones[c].proximal == bones.bones[b].distal and motion.is_descendant(index[c], k)]
        clip_dirs = [rest[t] - rest[k] for t in targets] or motion.child_directions(k)
        clip_dirs = [d / np.linalg.norm(d) for d in clip_dirs if np.linalg.norm(d) > 1e-9]
        if clip_dirs and np.linalg.norm(ours) > 1e-9:
            clip = np.mean(clip_dirs, axis=0)
            if np.linalg.norm(clip) > 1e-9:
                out[b] = (ours / np.linalg.norm(ours), clip / np.linalg.norm(clip))
    return out


def detect_axes(bones: BoneSkeleton, motion: Motion, index: dict[int, int], up: str = "auto",
                forward: str = "auto") -> tuple[str, str]:
    """The clip's up and forward axes: of the 24 axis-aligned frames, the one under which the
    mapped bones' rest directions agree best with ours.

    Arm bones do not vote (a T-pose clip and our arms-down rest disagree
    there); the spine, neck, legs, hips and feet do. With no such bone mapped,
    or when they leave forward undetermined, BVH's usual y up, z forward wins.
    A given ``up`` or ``forward`` (not ``"auto"``) is kept.
    """
    pairs = {b: d for b, d in rest_directions(bones, motion, index).items()
             if _part(bones.bones[b].label) not in ARM_PARTS}  # a T-pose and arms-down disagree there
    default = ("y" if up == "auto" else up), ("z" if forward == "auto" else forward)
    if not pairs:
        return default
    ours = np.array([o for o, _ in pairs.values()])
    clip = np.array([c for _, c in pairs.values()])
    names = [s + a for a in "xyz" for s in ("", "-")]
    candidates = [(u, f) for u in ([up] if up != "auto" else names) for f in ([forward] if forward != "auto" else names)
                  if u.lstrip("+-") != f.lstrip("+-")]
    # ties (only vertical bones mapped: forward is undetermined) go to the usual conventions
    usual = [default, ("y", "z"), ("z", "-y"), ("y", "-z"), ("z", "y")]
    candidates.sort(key=lambda c: usual.index(c) if c in usual else len(usual))
    best, best_score = default, -np.inf
    for u, f in candidates:
        score = float(np.einsum("ij,ij->", ours, clip @ axes_matrix(u, f).T))
        if score > best_score + 1e-6:
            best, best_score = (u, f), score
    return best


@dataclass
class Retarget:
    """A clip bound to our bones; :meth:`matrices` gives each frame's ``.trans`` matrices."""

    bones: BoneSkeleton
    motion: Motion
    mapping: dict[int, int]  # our bone index -> BVH joint index
    axes: np.ndarray
    scale: float  # BVH units -> voxels, for the root's displacement
    rest_align: np.ndarray  # (B, 3, 3) Q_b
    up: str = "y"  # the clip's axes, as given or detected
    forward: str = "z"

    @classmethod
    def build(cls, bones: BoneSkeleton, motion: Motion, mapping: dict[str, str] | None = None,
              up: str = "auto", forward: str = "auto") -> Retarget:
        mapping = suggest_mapping(bones, motion) if mapping is None else mapping
        index = {}
        for label, joint in mapping.items():
            try:
                b = bones.index(label)
            except KeyError:
                raise ValueError(f"the mapping names bone {label!r}, which the bone skeleton lacks") from None
            index[b] = motion.index(joint)
        if up == "auto" or forward == "auto":
            up, forward = detect_axes(bones, motion, index, up, forward)
        axes = axes_matrix(up, forward)
        rest = motion.rest_positions()
        align = np.tile(np.eye(3), (len(bones), 1, 1))
        for b, (ours, clip) in rest_directions(bones, motion, index).items():
            align[b] = _align(ours, axes @ clip)
        up_axis = axes.T @ OUR_UP  # the clip's up, in its own axes
        clip_height = rest[0] @ up_axis - min(p @ up_axis for p in motion.rest_points())
        roots = [b for b, p in enumerate(bones.parents()) if p is None]
        our_root = bones.joints[bones.bones[roots[0]].proximal] if roots else np.zeros(3)
        our_height = our_root @ OUR_UP - min(j @ OUR_UP for j in bones.joints.values())
        scale = our_height / clip_height if clip_height > 1e-9 and our_height > 0 else 1.0
        return cls(bones, motion, index, axes, float(scale), align, up, forward)

    def matrices(self, frames=slice(None)) -> np.ndarray:
        """``(F, B, 4, 4)`` row-vector matrices, rest voxel coordinates -> posed, one set per frame."""
        world_rot, world_pos = self.motion.forward_kinematics(frames)
        n, bones = len(world_rot), self.bones
        a = self.axes
        shift = (world_pos[:, 0] - world_pos[:1, 0]) @ a.T * self.scale  # root displacement, our axes
        parents = bones.parents()
        rot = np.empty((n, len(bones), 3, 3))
        out = np.zeros((n, len(bones), 4, 4))
        for b in parents_first(parents):
            p = parents[b]
            if b in self.mapping:
                rot[:, b] = a @ world_rot[:, self.mapping[b]] @ a.T @ self.rest_align[b]
            else:
                rot[:, b] = rot[:, p] if p is not None else np.eye(3)
            prox = bones.joints[bones.bones[b].proximal]
            if p is None:
                posed = prox + shift
            else:
                posed = prox @ out[:, p, :3, :3] + out[:, p, 3, :3]
            out[:, b, :3, :3] = np.swapaxes(rot[:, b], 1, 2)
            out[:, b, 3, :3] = posed - np.einsum("j,fjk->fk", prox, out[:, b, :3, :3])
            out[:, b, 3, 3] = 1.0
        return out

    def absorbed_degrees(self) -> dict[str, float]:
        """Per mapped bone, the rest-alignment angle: how far our rest bone is from the clip's."""
        from scipy.spatial.transform import Rotation

        return {self.bones.bones[b].label: float(np.degrees(Rotation.from_matrix(self.rest_align[b]).magnitude()))
                for b in sorted(self.mapping)}


def check_mapping_file(path, mapping: dict[str, str], bones: BoneSkeleton, motion: Motion) -> None:
    """Refuse a mapping that names bones or joints that do not exist, naming the file."""
    for label, joint in mapping.items():
        try:
            bones.index(label)
        except KeyError:
            raise FormatError(path, f"bone {label!r} is not in the bone skeleton") from None
        if joint not in motion.names:
            raise FormatError(path, f"BVH joint {joint!r} is not in the clip; it has {', '.join(motion.names)}")
