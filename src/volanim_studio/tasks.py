"""Long jobs of the studio, Qt-free (the Logic of Slicer's Widget/Logic split).

Each takes ``progress`` and ``cancel`` and returns a plain dict that the main
window hands to the Document on the GUI thread. The CLI's functions do the
work; nothing here knows a window exists.
"""

from __future__ import annotations

import numpy as np

from volanim_core import samples
from volanim_core.io import read_mskel, read_volume_grid
from volanim_core.progress import Reporter
from volanim_core.skeleton.hull import isosurface
from volanim_core.skeleton.skeletonize import DEFAULT_MIN_THINNESS, skeletonize
from volanim_core.volume import fill_cavities, threshold


def prepare_volume(volume: np.ndarray, *, lo: float, hi: float | None, fill: bool, metric: str = "euclid",
                   min_thinness: float = DEFAULT_MIN_THINNESS, skeleton_path=None, progress=None,
                   cancel=None) -> dict:
    """Segment, skeletonize and isosurface a loaded volume.

    ``skeleton_path``: a saved ``.mskel`` of this segmentation (a reopened
    project) is read instead of skeletonizing again.
    """
    report = Reporter(progress, cancel)
    report(0, 100)
    mask = threshold(volume, lo, hi).view(bool)
    if fill:
        mask = fill_cavities(mask)
    if not mask.any():
        raise ValueError(f"no voxel lies in the threshold range {lo}..{hi if hi is not None else 'max'}")
    report(10, 100)

    def sub(done, total):  # skeletonize's progress mapped onto 10..80 %
        report(10 + int(70 * done / max(total, 1)), 100)

    if skeleton_path:
        skel = read_mskel(skeleton_path)
    else:
        skel = skeletonize(mask, metric=metric, min_thinness=min_thinness, progress=sub, cancel=cancel)
    report(80, 100)
    verts, faces = isosurface(mask)
    report(100, 100)
    return {"volume": volume, "mask": mask, "skeleton": skel, "hull": (verts, faces), "skeleton_path": skeleton_path,
            "segmentation": {"lo": lo, "hi": hi, "fill": fill, "metric": metric, "min_thinness": min_thinness}}


def load_volume_file(path: str, dims=None) -> dict:
    """Read any supported volume (fast; the heavy part is :func:`prepare_volume`)."""
    data, origin, spacing = read_volume_grid(path, dims=dims)
    return {"volume": data, "spacing": spacing, "path": path}


def load_demo(name: str, *, skeleton_path=None, progress=None, cancel=None) -> dict:
    """A demo dataset, segmented, skeletonized (or its saved ``.mskel`` read) and with its hull."""
    s = samples.load(name)
    out = prepare_volume(s.volume, lo=s.mask_level, hi=None, fill=False, skeleton_path=skeleton_path,
                         progress=progress, cancel=cancel)
    out.update(spacing=s.spacing, sample=s)
    return out
