"""Where joint names go on screen: every name shown, none over another. Pure NumPy.

    joints' display positions --merge_coincident (within MERGE pixels)--> one label per place ("R_HIP / PELVIS_HIP")
    each label's text size --place (greedy, in the given order)--> its box: the first candidate beside its joint
        (above, right, left, below, then further out) that overlaps no box placed before it; when every
        candidate overlaps, the one overlapping least -- never hidden

Why: VTK's label placement culls a label that overlaps another, so on the hand-built mannequin R_SHOULDER and
R_HIP had no name at all; two actors (joint and bone names) printed over each other ("R_HIPPELVIS_HIP"). A
careful tool shows every name, moved aside, rather than dropping one quietly (#61).
"""

from __future__ import annotations

import numpy as np

MERGE = 3.0  # pixels: joints this close on screen share one label
PAD = 2.0  # pixels kept between two labels
GAP = 4.0  # pixels between a joint and its label


def merge_coincident(xy: np.ndarray, names: list[str], tol: float = MERGE) -> list[tuple[str, list[int]]]:
    """Groups of joints drawn at (nearly) one place, in the order of their first joint: ``(text, members)``."""
    groups: list[tuple[str, list[int]]] = []
    taken = np.zeros(len(names), bool)
    for i in range(len(names)):
        if taken[i]:
            continue
        near = np.flatnonzero(~taken & (np.linalg.norm(xy - xy[i], axis=1) <= tol))
        if i not in near:  # no picture yet (a window not shown): its place is not a number, it stands alone
            near = np.array([i])
        taken[near] = True
        groups.append((" / ".join(names[k] for k in near), [int(k) for k in near]))
    return groups


def _candidates(anchor: np.ndarray, size: np.ndarray) -> np.ndarray:
    """Lower-left corners of boxes beside ``anchor``, nearest first."""
    w, h = size
    x, y = anchor
    out = []
    for k in range(6):  # then the same sides, one line further out each time
        step = k * (h + PAD)
        out += [(x - w / 2, y + GAP + step), (x + GAP + step / 2, y - h / 2), (x - GAP - w - step / 2, y - h / 2),
                (x - w / 2, y - GAP - h - step), (x + GAP, y + GAP + step), (x - GAP - w, y + GAP + step),
                (x + GAP, y - GAP - h - step), (x - GAP - w, y - GAP - h - step)]
    return np.array(out, np.float64)


def _overlap(box: np.ndarray, placed: np.ndarray) -> np.ndarray:
    """Overlap area of ``box`` (x0, y0, x1, y1) with each of ``placed`` (M, 4), padded by PAD."""
    if not len(placed):
        return np.zeros(0)
    dx = np.minimum(box[2] + PAD, placed[:, 2]) - np.maximum(box[0] - PAD, placed[:, 0])
    dy = np.minimum(box[3] + PAD, placed[:, 3]) - np.maximum(box[1] - PAD, placed[:, 1])
    return np.clip(dx, 0, None) * np.clip(dy, 0, None)


def place(anchors: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """Boxes ``(N, 4)`` (x0, y0, x1, y1; display pixels, bottom-left origin) for labels of ``sizes`` (N, 2)
    beside ``anchors`` (N, 2), earlier labels first. No box covers an anchor of another label's joint."""
    anchors, sizes = np.asarray(anchors, np.float64), np.asarray(sizes, np.float64)
    dots = np.column_stack([anchors - 1.5, anchors + 1.5])  # every joint's dot stays readable
    placed = np.zeros((0, 4))
    for i in range(len(anchors)):
        best, best_cost = None, np.inf
        others = np.delete(dots, i, axis=0)
        for corner in _candidates(anchors[i], sizes[i]):
            box = np.concatenate([corner, corner + sizes[i]])
            cost = _overlap(box, placed).sum() + _overlap(box, others).sum()
            if cost < best_cost:
                best, best_cost = box, cost
                if cost == 0:
                    break
        if best is None:  # no picture yet (a window not shown: the anchors are not finite): beside it, as is
            best = np.concatenate([anchors[i], anchors[i] + sizes[i]])
        placed = np.vstack([placed, best])
    return placed
