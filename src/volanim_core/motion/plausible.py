"""Is a retargeted clip a person? Checks on our posed joints at sampled frames, before anything is written.

    the clip's kind (motion/kind.py) and our rig's -> the same kind, or the clip is refused whatever else holds
    Retarget.matrices(sampled frames) -> our joints posed (z up) -> per check: the share of frames it holds
        head above pelvis        the spine's top over its bottom: not on its back, not upside down
        feet near the floor      the lowest joint within half a leg of our rest floor (scale, up)
        knees and elbows bend    a limb's lower bone never folds back more than 165 degrees onto the upper
    a creature matched by its chains (motion/chains.py), along its own up:
        feet near the floor      the lowest foot within half a leg of the rest floor
        feet below the body      each foot lower than where its leg leaves the body (no leg flung over the back)

A check that holds in fewer than ``MOST`` of the frames names what is suspect
(the up axis, the scale, a bone's mapping), so ``bvh2trans`` refuses instead of
writing a figure on its back; ``--no-check`` writes it anyway.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .kind import rig_kind
from .presets import part_of

MOST = 0.8  # a check must hold in this share of the sampled frames (a jump leaves the floor, a bow dips the head)
FOLD_DEGREES = 165.0


@dataclass(frozen=True)
class Check:
    name: str
    held: float  # share of the sampled frames in which it held
    suspect: str  # what to look at when it fails
    whole: bool = False  # said of the clip as a whole (its figure's kind), not frame by frame

    @property
    def ok(self) -> bool:
        return self.held >= MOST

    def line(self, frames: int) -> str:
        state = "ok" if self.ok else f"FAILS: suspect {self.suspect}"
        if self.whole:
            return f"{self.name}: {'yes' if self.ok else 'no'}, over {frames} sampled frames ({state})"
        return f"{self.name}: {100 * self.held:.0f}% of {frames} sampled frames ({state})"

    def failure(self) -> str:
        """What failed, for a refusal."""
        if self.whole:
            return f"{self.name}: no ({self.suspect})"
        return f"{self.name} in only {100 * self.held:.0f}% of frames (suspect {self.suspect})"


def _posed(bones, mats: np.ndarray, joint: str) -> np.ndarray:
    b = next(i for i, bone in enumerate(bones.bones) if joint in (bone.proximal, bone.distal))
    return bones.joints[joint] @ mats[:, b, :3, :3] + mats[:, b, 3, :3]


def check_clip(retarget, samples: int = 64) -> tuple[list[Check], int]:
    """The checks that apply to this skeleton, at up to ``samples`` frames spread over the clip."""
    motion, bones = retarget.motion, retarget.bones
    frames = np.unique(np.linspace(0, motion.frames - 1, min(samples, motion.frames)).round().astype(int))
    mats = retarget.matrices(frames)
    checks = []
    figure = retarget.report.get("figure")  # a creature matched by its chains: its kind, read once
    clip, ours = retarget.report.get("kind"), (rig_kind(bones) if figure is None else figure.kind)
    # a mapping the user gave is their word (#86): a clip of one arm drives what it maps, so the figure's kind
    # is not asked, and only checks of bones it drives are made
    given = retarget.report.get("scheme") == "given"
    driven = set(retarget.mapping) if given else set(range(len(bones)))
    if clip is not None and ours is not None and not given:  # first: a quadruped's steps pass a person's checks
        checks.append(Check(f"the clip's figure is a {ours}, as the rig", float(clip.kind == ours),
                            f"it is {'a ' if clip.kind != 'other' else ''}{clip.kind}: {clip.reason}; "
                            "a clip drives a rig of its own kind", whole=True))
    if figure is not None:
        checks += _creature_checks(bones, mats, figure, retarget, driven)
    by_part = {part_of(b.label): k for k, b in enumerate(bones.bones)}
    spine = by_part.get((None, "SPINE"))
    if spine is not None and spine in driven and ours != "quadruped":  # a quadruped's spine lies level
        bone = bones.bones[spine]
        top, bottom = _posed(bones, mats, bone.distal), _posed(bones, mats, bone.proximal)
        held = float(np.mean(top[:, 2] > bottom[:, 2]))
        checks.append(Check("head above pelvis", held, f"the up axis (up {retarget.up}; give another with --up)"))
    legs = [by_part[(s, "SHIN")] for s in "LR" if (s, "SHIN") in by_part]
    if legs and set(legs) <= driven:
        rest_floor = min(j[2] for j in bones.joints.values())
        leg = max(np.linalg.norm(bones.joints[bones.bones[b].distal] - bones.joints[bones.bones[b].proximal])
                  for b in legs)
        lowest = np.min([_posed(bones, mats, j)[:, 2] for j in bones.joints], axis=0)
        held = float(np.mean(np.abs(lowest - rest_floor) <= 0.5 * leg))  # a crouch keeps a foot down; a jump is brief
        checks.append(Check("feet near the floor", held, f"the scale ({retarget.scale:.3g} voxels per BVH unit, "
                                                         f"{retarget.report.get('scale', '')}) or the up axis"))
    for upper, lower, name in (("THIGH", "SHIN", "knee"), ("UPPERARM", "FOREARM", "elbow")):
        for side in "LR":
            a, b = by_part.get((side, upper)), by_part.get((side, lower))
            if a is None or b is None or b not in retarget.mapping:
                continue
            da = _direction(bones, mats, a)
            db = _direction(bones, mats, b)
            angle = np.degrees(np.arccos(np.clip(np.einsum("fi,fi->f", da, db), -1, 1)))
            held = float(np.mean(angle < FOLD_DEGREES))
            label = bones.bones[b].label
            checks.append(Check(f"{side} {name} bends less than {FOLD_DEGREES:.0f} degrees", held,
                                f"the mapping of {label} ({motion.names[retarget.mapping[b]]})"))
    return checks, len(frames)


def refuse_failed(path, checks: list[Check], suggested: dict[str, str] | None = None) -> None:
    """Raise ValueError naming the clip and every failed check (``bvh2trans``, ``sequence``): nothing is
    written from a clip that does not look like the rig's figure standing. ``suggested``: the mapping found
    from the names (bone -> clip joint), shown as a map file when the clip is of part of a body."""
    failed = [c for c in checks if not c.ok]
    if failed:
        part = ""
        if suggested and any(c.whole and "it is other" in c.suspect for c in failed):
            lines = "; ".join(f"'{bone} {joint}'" for bone, joint in suggested.items())
            part = (". A clip of part of a body (an arm, a hand) drives the bones a map file names and leaves "
                    f"the rest at rest: for example a file of the lines {lines}, given with --map FILE")
        raise ValueError(f"{path}: the retargeted clip does not look like the rig's figure standing: "
                         + "; ".join(c.failure() for c in failed) + part
                         + ". Nothing was written; give --up/--forward/--map, or --no-check to write it anyway")


def _creature_checks(bones, mats: np.ndarray, figure, retarget, driven: set[int]) -> list[Check]:
    """The checks of a creature's figure (:class:`~.chains.Figure`), along its own up."""
    names = figure.names
    bone_at = {b.distal: k for k, b in enumerate(bones.bones)}
    legs = [path for pair in figure.legs for path in pair.values()]
    if not legs or not {bone_at[names[n]] for path in legs for n in path[1:]} <= driven:
        return []
    up = figure.up
    feet = np.stack([_posed(bones, mats, names[path[-1]]) @ up for path in legs], axis=1)  # (F, legs)
    forks = np.stack([_posed(bones, mats, names[path[0]]) @ up for path in legs], axis=1)
    rest_floor = min(figure.points[path[-1]] @ up for path in legs)
    leg = float(np.mean([figure.reach(path) for path in legs]))
    suspect = f"the scale ({retarget.scale:.3g} voxels per BVH unit) or the up axis (up {retarget.up})"
    return [Check("feet near the floor", float(np.mean(np.abs(feet.min(axis=1) - rest_floor) <= 0.5 * leg)), suspect),
            Check("feet below the body", float(np.mean((feet < forks).all(axis=1))),
                  f"the up axis (up {retarget.up}) or the legs' chains ({', '.join(figure.chains())})")]


def _direction(bones, mats, b: int) -> np.ndarray:
    bone = bones.bones[b]
    d = _posed(bones, mats, bone.distal) - _posed(bones, mats, bone.proximal)
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
