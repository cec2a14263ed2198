"""The mannequin's true shape in any pose: its capsules moved by the bones' matrices.

    .trans matrices (B, 4, 4), rest voxels -> posed
      --capsule_boxes: each capsule's moved box; their union is the posed grid (origin, shape)
      --paint_mannequin(matrices): each posed voxel read at the rest point its capsule's bone brings there
      --> Sample(volume = tissue, part = bone index + 1, origin = where voxel [0, 0, 0] is in the rest grid)

The mannequin is built analytically (:mod:`volanim_core.mannequin_body`: a tapered capsule per bone
part, each voxel in the part where it lies deepest, tissue by depth), so posing the capsules gives, for
any pose, the shape and tissue the posed body should have: an oracle every reconstruction method can be
scored on (:mod:`volanim_core.reconstruct.shape`).

What this truth is: rigid parts, each moved whole by its bone, meeting where they overlap (the capsules
round off each joint like a ball joint). What it is not: skin that stretches or folds, muscle that
bulges, flesh that slides over bone. Where two capsules meet at a bent joint, the truth keeps the deeper
one's voxel; the crease inside a bend is the capsules' own, not a person's. At identity matrices it is
the rest sample voxel for voxel (a test).

The colour mannequin's truth is the grey truth's tissues in :data:`~volanim_core.samples.TISSUE_COLOURS`,
without the rest sample's shading and grain (a per-voxel random draw has no posed counterpart).
"""

from __future__ import annotations

import numpy as np

from volanim_core.mannequin_body import (
    FULL_SHAPE,
    LARGE_SHAPE,
    MANNEQUIN_SHAPE,
    capsule_boxes,
    mannequin_bones_at,
    paint_mannequin,
)
from volanim_core.samples import TISSUE_COLOURS, Sample

POSABLE = ("mannequin", "mannequin-large", "mannequin-full", "mannequin-colour")
_SCALES = {"mannequin": np.ones(3), "mannequin-colour": np.ones(3),
           "mannequin-large": np.array(LARGE_SHAPE, float) / MANNEQUIN_SHAPE,
           "mannequin-full": np.array(FULL_SHAPE, float) / MANNEQUIN_SHAPE}


def posed_sample(name: str, matrices: np.ndarray, progress=None) -> Sample:
    """The sample ``name`` (one of :data:`POSABLE`) posed by ``matrices`` (B, 4, 4), one per bone of its
    ``.bones`` in root order (a ``.trans`` of its bones; ``pose_matrices``): the body's true posed
    shape on a grid just holding it, ``origin`` where its voxel ``[0, 0, 0]`` lies in the rest grid.
    ``progress(done, total)`` counts body parts.
    """
    if name not in POSABLE:
        raise ValueError(f"only the mannequins have a posed truth ({', '.join(POSABLE)}), not {name!r}")
    scale = _SCALES[name]
    bones = mannequin_bones_at(scale)
    matrices = np.asarray(matrices, np.float64)
    if matrices.shape != (len(bones), 4, 4) or not np.isfinite(matrices).all():
        raise ValueError(f"{name} has {len(bones)} bones: the pose needs {len(bones)} finite 4x4 matrices, "
                         f"got an array of shape {matrices.shape}")
    boxes = capsule_boxes(bones, scale, matrices)
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    tissue, part = paint_mannequin(bones, scale, tuple(int(v) for v in hi - lo + 1), lo, matrices, progress)
    tissue, part, origin = _tight(tissue, part, lo)
    if name == "mannequin-colour":
        table = np.zeros((256, 3), np.uint8)
        for value, colour in TISSUE_COLOURS.items():
            table[value] = colour
        tissue = table[tissue]
    return Sample(f"{name} posed", tissue, bones, part, origin=origin)


def _tight(tissue: np.ndarray, part: np.ndarray, lo: np.ndarray):
    """The volumes cut to the body's own box (the capsules' boxes are larger than the capsules)."""
    found = np.nonzero(part.any(axis=(1, 2)))[0], np.nonzero(part.any(axis=(0, 2)))[0], \
        np.nonzero(part.any(axis=(0, 1)))[0]
    if any(len(f) == 0 for f in found):
        return tissue, part, tuple(int(v) for v in lo)
    cut = tuple(slice(int(f[0]), int(f[-1]) + 1) for f in found)
    return tissue[cut], part[cut], tuple(int(lo[i] + found[i][0]) for i in range(3))
