"""A humanoid's shoulders and hips read off the body itself, not off the thinned curve.

The thinned curve rounds every corner: where an arm meets a torso it leaves the torso below the
clavicles, and where the legs meet it forks below the hips, the more so the taller the body is in
voxels (mannequin-large's torso, 3.1 voxels to the mannequin's one upwards, put its shoulders 25-30
voxels low). The body's outline has landmarks that do not move with the curve:

    upper arm's line, the spine's line (from the curve; both straight enough)
      --march up from the elbow's level-->  the ARMPIT: the highest level where the segment from
                                            the arm to the spine crosses background
      --along the arm's line, up-->         the TOP of the shoulder: where that line leaves the body
      SHOULDER = ARMPIT_TO_TOP of the way from the armpit to the top (the humeral head sits about
                 two thirds up from the axilla to the acromion)
    both thighs' lines
      --march up from the knees' level-->   the CROTCH: the highest level with background between them
      --largest torso section above it-->   HIPS at the level where the torso's cross-section (seen
                                            from the spine: a hanging arm across background is not in
                                            it) is largest, within WAIST of the way from the crotch to
                                            the armpits (the greater trochanters' level)

Every measure is a ratio along one line or a comparison at one level, so a body stretched along its
spine (anisotropic voxels) keeps its landmarks. Each function returns None when the body does not
show its landmark (an arm pressed to the torso, legs together): the caller keeps the curve's guess.
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.curve_skeleton import Body

ARMPIT_TO_TOP = 0.6
WAIST = 0.5
STEEP = 0.3  # a line must rise at least this much (cosine with the spine) to be met at a level


Line = tuple[np.ndarray, np.ndarray]  # (a point on it, unit direction)


def at_level(line: Line, up: np.ndarray, level: float) -> np.ndarray:
    """Where ``line`` crosses the plane ``x @ up == level``."""
    centre, axis = line
    return centre + ((level - centre @ up) / (axis @ up)) * axis


def _levels(body: Body, lo: float, hi: float) -> np.ndarray:
    return np.arange(lo, hi, 0.5 * body.step)


def gap_top(body: Body, a: Line, b: Line, up: np.ndarray, lo: float, hi: float) -> float | None:
    """Marching up from ``lo``: the last level of the first run of levels where the segment between
    lines ``a`` and ``b`` crosses background (an armpit, a crotch); None if there is no such run or
    a line runs across ``up``."""
    if min(abs(a[1] @ up), abs(b[1] @ up)) < STEEP:
        return None
    top = None
    for h in _levels(body, lo, hi):
        if not body.clear(at_level(a, up, h), at_level(b, up, h)):
            top = h
        elif top is not None:
            return top
    return None  # background all the way up: no landmark in this range


def shoulder(body: Body, arm: Line, spine: Line, up: np.ndarray, lo: float,
             hi: float) -> tuple[np.ndarray, float] | None:
    """The shoulder joint on the upper arm's line ``arm`` and the armpit's level: ``ARMPIT_TO_TOP``
    of the way from the armpit (between levels ``lo`` and ``hi``) up to where the line leaves the body."""
    armpit = gap_top(body, arm, spine, up, lo, hi)
    if armpit is None:
        return None
    start = at_level(arm, up, armpit)
    rising = arm[1] if arm[1] @ up > 0 else -arm[1]
    top = body.exit(start, rising)
    return start + ARMPIT_TO_TOP * (top - start), armpit


def area(body: Body, centre: np.ndarray, up: np.ndarray, side: np.ndarray, rays: int = 48) -> float:
    """The area of the body's cross-section across ``up`` around ``centre``, seen from ``centre``
    (a star-shaped outline from ``rays`` rays: a limb beside the torso, across background, is not in it)."""
    fwd = np.cross(up, side)
    angles = np.linspace(0, 2 * np.pi, rays, endpoint=False)
    reach = [np.linalg.norm(body.exit(centre, np.cos(a) * side + np.sin(a) * fwd) - centre) for a in angles]
    return float(0.5 * np.sum(np.square(reach)) * 2 * np.pi / rays)


def hip_level(body: Body, thighs: tuple[Line, Line], spine: Line, side: np.ndarray, up: np.ndarray,
              lo: float, armpits: float) -> float | None:
    """The level of the hip joints: where the torso's cross-section is largest, between the crotch
    (marching up from ``lo``) and ``WAIST`` of the way on to ``armpits``."""
    crotch = gap_top(body, thighs[0], thighs[1], up, lo, armpits)
    if crotch is None:
        return None
    levels = _levels(body, crotch + body.step, crotch + WAIST * (armpits - crotch))
    if len(levels) == 0:
        return None
    sizes = np.array([area(body, at_level(spine, up, h), up, side) for h in levels])
    widest = np.flatnonzero(sizes >= sizes.max() * 0.99)
    return float(levels[widest].mean())  # the middle of a plateau, not its first level
