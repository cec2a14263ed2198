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
of leg lengths (thigh + shin: OFFSET lengths, true whatever the rest pose).

Which joint drives which bone (:func:`match`) is read from the names in the
scheme that explains most of them (``presets.py``) and from the clip's shape
and motion (``body.py``); each line says which of the two placed it. Up and
facing come from the motion (feet lowest, feet pointing forward), so a clip
whose rest pose is not a T-pose (LAFAN's lies along x) lands upright; such a
clip's rest differences are measured at its most upright sampled frame
instead of at its OFFSET pose.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io.bvh_files import Motion
from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.pose import least_rotation, parents_first

from .body import (
    Sampled,
    chain_length,
    facing_at,
    nearest_axis,
    read_body,
    sample,
    units_of,
    up_over,
    upright,
)
from .chains import ChainMatch, match_chains
from .kind import clip_kind, rig_kind
from .presets import best_preset, part_key, part_of

AXES = {"x": 0, "y": 1, "z": 2}
OUR_UP, OUR_FORWARD = np.array([0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0])  # volanim's figures: z up, facing -y

ARM_PARTS = {"CLAVICLE", "UPPERARM", "FOREARM", "HAND"}


def _part(label: str) -> str:
    """``L_UPPERARM`` -> ``UPPERARM``: the body part of one of our bone labels."""
    return part_of(label)[1]


@dataclass
class Match:
    """Our bone label -> BVH joint name, with how each was placed and by which naming scheme."""

    mapping: dict[str, str]
    how: dict[str, str]  # label -> "name and shape", "name", "shape", or "name (shape says X)"
    scheme: str
    notes: list[str]
    chains: ChainMatch | None = None  # how a rig of another kind than ours was matched chain to chain


def match(bones: BoneSkeleton, motion: Motion, sampled: Sampled | None = None) -> Match:
    """Which BVH joint drives each of our bones, from names and shape together (module docstring).

    A clip with a joint named as each of our bones (``volanim trans2bvh`` wrote it) maps each bone to its
    own joint. Pelvis bones (``L_PELVIS``, from the root joint sideways) follow the BVH root. Where the name
    and the shape disagree, the name wins when its joint lies in the limb the shape found (a
    scheme's finer choice inside a limb), the shape wins otherwise (a name that means another limb).
    """
    if all(b.label in motion.names for b in bones.bones):  # a clip volanim wrote for these bones (trans2bvh)
        own = {b.label: b.label for b in bones.bones}
        return Match(own, dict.fromkeys(own, "its own joint (a clip volanim wrote)"), "volanim trans2bvh", [])
    if rig_kind(bones, by_shape=False) != "biped":  # a creature: matched by its chains, names aside (#86)
        chained, why = match_chains(bones, motion)
        if chained is not None:
            return Match(chained.mapping, chained.how, f"chains ({chained.rig.kind})", [], chained)
    preset, named = best_preset(motion.names)
    s = sampled if sampled is not None else sample(motion)
    body = read_body(motion, s)
    shaped = body.parts
    limb_of = _limbs(shaped)
    mapping, how = {}, {}
    for b in bones.bones:
        side, part = part_of(b.label)
        if part in ("PELVIS", "HIPS"):
            mapping[b.label], how[b.label] = motion.names[0], "the root"
            continue
        key = part_key(side, part)
        n, sh = named.get(key), shaped.get(key)
        if n is not None and sh is not None and n != sh:
            same_limb = limb_of.get(key) is not None and limb_of[key] == limb_of.get(_key_of(shaped, n))
            pick = n if same_limb or motion.is_descendant(n, sh) or motion.is_descendant(sh, n) else sh
            mapping[b.label] = motion.names[pick]
            how[b.label] = (f"name (shape says {motion.names[sh]})" if pick == n
                            else f"shape (name says {motion.names[n]})")
        elif n is not None or sh is not None:
            mapping[b.label] = motion.names[n if n is not None else sh]
            how[b.label] = "name and shape" if n == sh else ("name" if n is not None else "shape")
    return Match(mapping, how, preset.name if named else "none", body.notes)


def _limbs(parts: dict[str, int]) -> dict[str, str]:
    """Part key -> its limb (``L_arm``, ``R_leg``, ``trunk``)."""
    out = {}
    for key in parts:
        side, part = part_of(key)
        out[key] = f"{side}_{'arm' if part in ARM_PARTS else 'leg'}" if side else "trunk"
    return out


def _key_of(parts: dict[str, int], joint: int) -> str | None:
    return next((k for k, j in parts.items() if j == joint), None)


def suggest_mapping(bones: BoneSkeleton, motion: Motion) -> dict[str, str]:
    """Our bone label -> BVH joint (:func:`match`'s mapping)."""
    return match(bones, motion).mapping


def axis_vector(text: str) -> np.ndarray:
    """``"-z"`` -> (0, 0, -1): a signed axis name as a unit vector."""
    text = text.strip().lower()
    sign = -1.0 if text.startswith("-") else 1.0
    key = text.lstrip("+-")
    if key not in AXES:
        raise ValueError(f"an axis must be x, y or z (optionally signed), got {text!r}")
    v = np.zeros(3)
    v[AXES[key]] = sign
    return v


def axes_matrix(up: str = "y", forward: str = "z") -> np.ndarray:
    """A: BVH world -> ours, from the clip's up and forward axes (``"y"``, ``"-z"``, ...)."""
    u, f = axis_vector(up), axis_vector(forward)
    if abs(u @ f) > 0.5:
        raise ValueError(f"up ({up}) and forward ({forward}) must be different axes")
    source = np.column_stack([u, f, np.cross(f, u)])  # up, forward, right in BVH axes
    target = np.column_stack([OUR_UP, OUR_FORWARD, np.cross(OUR_FORWARD, OUR_UP)])
    return target @ source.T


def rest_pose(motion: Motion) -> tuple[np.ndarray, np.ndarray]:
    """``(joints, tips)`` at the OFFSET pose: each joint and where its bone points to (longest child,
    else End Site, else itself)."""
    joints = motion.rest_positions()
    tips = joints.copy()
    for j in range(len(joints)):
        dirs = motion.child_directions(j)
        if dirs:
            tips[j] = joints[j] + dirs[0]
    return joints, tips


def rest_directions(bones: BoneSkeleton, motion: Motion, index: dict[int, int], pose=None) -> dict[int, tuple]:
    """Per mapped bone: (our rest direction, the clip's direction in BVH axes at ``pose``), unit vectors.

    ``pose``: ``(joints, tips)`` of the clip's reference (its OFFSET pose by default). The clip's
    direction points from the bone's joint towards the joints that drive its child bones (or to
    its tip when none is mapped).
    """
    joints, tips = pose if pose is not None else rest_pose(motion)
    out = {}
    for b, k in index.items():
        ours = bones.joints[bones.bones[b].distal] - bones.joints[bones.bones[b].proximal]
        targets = [index[c] for c in range(len(bones)) if c in index and
                   bones.bones[c].proximal == bones.bones[b].distal and motion.is_descendant(index[c], k)]
        clip_dirs = [joints[t] - joints[k] for t in targets] or [tips[k] - joints[k]]
        clip_dirs = [d / np.linalg.norm(d) for d in clip_dirs if np.linalg.norm(d) > 1e-9]
        if clip_dirs and np.linalg.norm(ours) > 1e-9:
            clip = np.mean(clip_dirs, axis=0)
            if np.linalg.norm(clip) > 1e-9:
                out[b] = (ours / np.linalg.norm(ours), clip / np.linalg.norm(clip))
    return out


def detect_axes(bones: BoneSkeleton, motion: Motion, index: dict[int, int], up: str = "auto",
                forward: str = "auto", sampled: Sampled | None = None):
    """The clip's up and forward axes, what decided them, and the pose the rest differences are
    measured at: ``(up, forward, how, reference, pose)``.

    Up from the motion (feet lowest over the sampled frames). The reference pose is the clip's
    OFFSET pose when it stands upright in it, else its most upright sampled frame (LAFAN's
    OFFSET pose lies along x). Forward is where that pose faces (:func:`~.body.facing_at`).
    A given ``up`` or ``forward`` (not ``"auto"``) is kept. When the motion cannot tell (no head
    or feet mapped), of the 24 axis-aligned frames the one under which the mapped non-arm bones'
    rest directions agree best with ours; then BVH's usual y up, z forward.
    """
    s = sampled if sampled is not None else sample(motion)
    parts = {part_key(*part_of(bones.bones[b].label)): k for b, k in index.items()}
    up_v = up_over(s, parts)
    if up == "auto" and up_v is not None:
        up = nearest_axis(up_v)[0]
    if up == "auto":
        up, forward = _axes_from_rest(bones, motion, index, up, forward)
        return up, forward, "from the rest pose (no head and feet mapped)", None, None
    up_clip = axis_vector(up)
    reference, pose = None, rest_pose(motion)
    if upright(*pose, parts, up_clip) < 0.7:  # not standing at rest: LAFAN lies along x
        best = int(np.argmax([upright(s.joints[i], s.tips[i], parts, up_clip) for i in range(len(s.frames))]))
        reference, pose = int(s.frames[best]), (s.joints[best], s.tips[best])
    at = "its rest pose" if reference is None else f"frame {reference}"
    if forward != "auto":
        return up, forward, f"up from the motion, forward given (rest measured at {at})", reference, pose
    fwd_v, told = facing_at(*pose, parts, up_clip)
    if fwd_v is None:
        forward = _axes_from_rest(bones, motion, index, up, "auto")[1]
        return up, forward, f"up from the motion, forward from the rest directions ({told})", reference, pose
    return up, nearest_axis(fwd_v, exclude=up)[0], f"from the motion (facing from {told} at {at})", reference, pose


def _axes_from_rest(bones, motion, index, up, forward) -> tuple[str, str]:
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


def _bone_of(bones: BoneSkeleton, side: str, part: str) -> int | None:
    return next((b for b in range(len(bones)) if part_of(bones.bones[b].label) == (side, part)), None)


def _legs(bones: BoneSkeleton, motion: Motion, index: dict[int, int]) -> list[tuple[float, float]]:
    """Per leg mapped in both: (our thigh + shin, the clip's hip-to-ankle length in its units)."""
    out = []
    for side in "LR":
        thigh, shin, foot = (_bone_of(bones, side, p) for p in ("THIGH", "SHIN", "FOOT"))
        if None in (thigh, shin, foot) or thigh not in index or foot not in index:
            continue
        clip = chain_length(motion, index[thigh], index[foot])
        ours = sum(float(np.linalg.norm(bones.joints[bones.bones[b].distal] - bones.joints[bones.bones[b].proximal]))
                   for b in (thigh, shin))
        if clip > 1e-9 and ours > 0:
            out.append((ours, clip))
    return out


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
    reference: int | None = None  # the clip frame taken as its rest (None: its OFFSET pose)
    report: dict = field(default_factory=dict)  # how axes, units and mapping were found (printed)

    @classmethod
    def build(cls, bones: BoneSkeleton, motion: Motion, mapping: dict[str, str] | None = None,
              up: str = "auto", forward: str = "auto") -> Retarget:
        s = sample(motion)
        found = match(bones, motion, s) if mapping is None else Match(
            mapping, dict.fromkeys(mapping, "given"), "given", [])
        index = {}
        for label, joint in found.mapping.items():
            try:
                b = bones.index(label)
            except KeyError:
                raise ValueError(f"the mapping names bone {label!r}, which the bone skeleton lacks") from None
            index[b] = motion.index(joint)
        chained = found.chains
        if chained is None and mapping is not None and rig_kind(bones, by_shape=False) != "biped":
            chained = match_chains(bones, motion)[0]  # a creature's axes are its own, whoever mapped it
        if chained is not None:  # its figure's up and forward onto ours: a cow's volume need not stand in z
            given = [None if a == "auto" else axis_vector(a) for a in (up, forward)]
            axes, reference, pose = chained.axes(*given), None, rest_pose(motion)
            up, forward = nearest_axis(axes.T @ chained.rig_frame[:, 2])[0], \
                nearest_axis(axes.T @ chained.rig_frame[:, 0])[0]
            axes_how = ("given" if any(g is not None for g in given) else
                        "from the figures (feet lowest, hind legs to front legs), the clip's and the rig's")
        else:
            up, forward, axes_how, reference, pose = detect_axes(bones, motion, index, up, forward, s)
            axes = axes_matrix(up, forward)
        up_clip = axes.T @ OUR_UP  # the clip's up, in its own axes
        align = np.tile(np.eye(3), (len(bones), 1, 1))
        # a creature keeps its own build: two kinds' rest directions differ by build, not by pose (a cow's
        # horn is no elephant's head), so only the clip's motion from its rest is applied (Q_b = I)
        for b, (ours, clip) in ({} if chained is not None else rest_directions(bones, motion, index, pose)).items():
            align[b] = least_rotation(ours, axes @ clip)
        legs = _legs(bones, motion, index)
        if chained is not None:
            scale, scale_how, units = chained.scale, "leg length (the legs' chains)", units_of(chained.clip_leg)
        elif legs:
            scale = float(np.mean([ours / clip for ours, clip in legs]))
            scale_how, units = "leg length (hip to ankle)", units_of(float(np.mean([c for _, c in legs])))
        else:
            rest = motion.rest_positions()
            clip_height = rest[0] @ up_clip - min(p @ up_clip for p in motion.rest_points())
            roots = [b for b, p in enumerate(bones.parents()) if p is None]
            our_root = bones.joints[bones.bones[roots[0]].proximal] if roots else np.zeros(3)
            our_height = our_root @ OUR_UP - min(j @ OUR_UP for j in bones.joints.values())
            scale = our_height / clip_height if clip_height > 1e-9 and our_height > 0 else 1.0
            scale_how, units = "hip height at rest", "unknown"
        report = {"scheme": found.scheme, "how": found.how, "notes": found.notes, "axes": axes_how,
                  "scale": scale_how, "reference": reference, "units": units, "kind": clip_kind(motion, s),
                  "figure": None if chained is None else chained.rig}
        return cls(bones, motion, index, axes, float(scale), align, up, forward, reference, report)

    def matrices(self, frames=slice(None)) -> np.ndarray:
        """``(F, B, 4, 4)`` row-vector matrices, rest voxel coordinates -> posed, one set per frame."""
        world_rot, world_pos = self.motion.forward_kinematics(frames)
        if self.reference is not None:  # rotations from the reference frame, not from the OFFSET pose
            ref_rot, _ = self.motion.forward_kinematics([self.reference])
            world_rot = world_rot @ np.swapaxes(ref_rot, -1, -2)
        n, bones = len(world_rot), self.bones
        a = self.axes
        shift = (world_pos[:, 0] - world_pos[:1, 0]) @ a.T * self.scale  # root displacement, our axes
        parents = bones.parents()
        if not any(p is None and b in self.mapping for b, p in enumerate(parents)):  # no root bone driven (a
            shift[:] = 0.0  # clip of one arm, mapped so): the body stays where it stands, the arm turns (#86)
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
