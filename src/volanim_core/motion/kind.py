"""What a clip moves: a biped, a quadruped or something else, read from its shape and motion, names aside.

    the tree       -> the hips: the first joint with several branches; the upper body (most joints)
                      and, among the others, the longest pair of twins (same joints, same reach): the legs
                   -> the upper body's first fork: its longest pair of twins (arms, or front legs)
    sampled frames -> per frame, in the clip's own axes: spine (hips -> that fork), hind (from where the
       (FK)           legs leave to their tips, the pair's mean) and fore (likewise)
    median angles  -> biped      the legs reach away from the upper body (hind at >= BIPED from the spine)
                      quadruped  both pairs reach across the spine (hind within ACROSS of 90 degrees)
                                 and the same way (fore within SAME of hind)
                      other      no twin legs, no twin arms, or neither rule
    (first: three pairs of legs or more along one body, read as chains, motion/chains.py: many-legged)

Names cannot tell: 3ds Max's biped (``Bip01 L Thigh``) rigs elephants and horses too, with the front
legs named as arms. Gravity is not needed either: the angles are between the clip's own limbs, so
a clip on its side is still what it is. A human sitting reaches its legs forward and its arms down
(not the same way); one crawling on all fours is, while it crawls, a quadruple: the rule is taken
over the clip's sampled frames, by the median.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.io.bvh_files import Motion

from .body import Sampled, children, longest_path, reach, sizes, twins
from .chains import ACROSS, clip_figure, rig_figure
from .presets import part_of

BIPED = 120.0  # degrees between the spine and the legs: a person's are near 180, sitting near 135
# and its front and hind legs reach the same way, within this: a gallop stretches them fore and aft (the
# Fox's run, Khronos' glTF sample: 53 degrees, median over its frames); a person sitting, 90
SAME = 60.0


@dataclass(frozen=True)
class Kind:
    kind: str  # "biped", "quadruped", "many-legged" or "other"
    reason: str


def _angles(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1)
    return np.degrees(np.arccos(np.clip(np.einsum("fi,fi->f", u, v) / np.maximum(n, 1e-12), -1, 1)))


def clip_kind(motion: Motion, s: Sampled) -> Kind:
    """The kind of the clip's figure, and the reason in words (printed by ``bvh2trans``)."""
    figure = clip_figure(motion)
    if figure.kind == "many-legged":  # three pairs or more: no biped's or quadruped's reading applies (#86)
        return Kind("many-legged", figure.reason)
    kids, far, size = children(motion), reach(motion), sizes(motion)
    pairs = [p for j in range(len(motion.names)) for p in _pairs(motion, size, far, kids[j])]
    if len(pairs) < 2:
        return Kind("other", f"{'one pair' if pairs else 'no pair'} of twin limbs, not two")
    pairs = sorted(pairs, key=lambda p: -(far[p[0]] + far[p[1]]))[:2]  # not a hand's fingers

    def start(pair):  # (S, 3): where the pair leaves the body
        return s.joints[:, list(pair)].mean(axis=1)

    rest = motion.rest_positions()
    legs, arms = sorted(pairs, key=lambda p: np.linalg.norm(rest[list(p)].mean(axis=0) - rest[0]))  # legs: hips
    hind, fore = _limb(motion, s, kids, far, legs), _limb(motion, s, kids, far, arms)
    spine = start(arms) - start(legs)
    hind_spine = float(np.median(_angles(hind, spine)))
    fore_hind = float(np.median(_angles(fore, hind)))
    said = f"legs at {hind_spine:.0f} degrees from the spine, arms or front legs at {fore_hind:.0f} from the legs"
    if hind_spine >= BIPED:
        return Kind("biped", f"the legs reach away from the upper body ({said})")
    if abs(hind_spine - 90) <= ACROSS and fore_hind <= SAME:
        return Kind("quadruped", f"both pairs of limbs reach across the spine, the same way ({said})")
    return Kind("other", f"neither a biped's legs nor a quadruped's ({said})")


def _pairs(motion: Motion, size, far, siblings: list[int]) -> list[tuple[int, int]]:
    """Twin pairs among one joint's children, longest first (a root may carry both legs and arms)."""
    out, left = [], list(siblings)
    while (pair := twins(motion, size, far, left)) is not None:
        out.append(pair)
        left = [c for c in left if c not in pair]
    return out


def _limb(motion: Motion, s: Sampled, kids, far, pair) -> np.ndarray:
    """(S, 3): from where the pair leaves the body to its tips, the two limbs' mean, per sampled frame."""
    out = np.zeros((len(s.frames), 3))
    for b in pair:
        end = longest_path(motion, b, far, kids)[-1]
        out += s.tips[:, end] - s.joints[:, b]
    return out / len(pair)


def rig_kind(bones, by_shape: bool = True) -> str | None:
    """The kind our bones are, by their names (the auto-rig templates' and the mannequin's), else by their
    shape (:func:`.chains.read_figure`: an auto-rig's chains, ``ANT2_1``, name no part); None when neither
    says (``by_shape=False``: the names alone)."""
    parts = {part_of(b.label) for b in bones.bones}
    if ("L", "UPPERARM") in parts and ({("L", "THIGH"), ("L", "SHIN")} & parts):
        return "biped"
    if ("L", "HUMERUS") in parts and ("L", "FEMUR") in parts:
        return "quadruped"
    if not by_shape:
        return None
    kind = rig_figure(bones).kind
    return None if kind == "other" else kind
