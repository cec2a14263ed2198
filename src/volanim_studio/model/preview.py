"""Preview reconstructions for the studio: full or reduced resolution, plus the report. Qt-free.

A reduced preview reconstructs on a ``factor``-times coarser grid: the bone
matrices are followed by a 1/factor scale and radii shrink alike, so the
voxel count (the cost) drops by factor^3 while the shape stays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.reconstruct.breakage import BreakageReport, RestParts, breakage_report
from volanim_core.reconstruct.engine import Reconstruction, reconstruct
from volanim_core.rig.connectivity import Tskel
from volanim_core.rig.tskel_tools import coarse_tskel


@dataclass
class Preview:
    reconstruction: Reconstruction
    factor: int
    mode: str
    report: BreakageReport | None = None
    rest_parts: RestParts | None = None  # what the report used, for the caller to keep
    joints: dict | None = None  # the posed joints it was made for: playing, the bones drawn are these
    frame: int | None = None  # the timeline frame it shows (None: not a frame of the timeline)

    @property
    def spacing(self) -> tuple[float, float, float]:
        return (float(self.factor),) * 3

    @property
    def origin_voxels(self) -> np.ndarray:
        """Where voxel [0, 0, 0] of the preview sits, in full-resolution voxel coordinates."""
        return np.asarray(self.reconstruction.origin, np.float64) * self.factor


def make_preview(tskel: Tskel, *, mode: str = "bone", kernel: int = 1, padding: int = 2, source=None,
                 factor: int = 1, joints=None, posed_joints=None, report: bool = False,
                 rest_parts: RestParts | None = None, progress=None, cancel=None) -> Preview:
    """Reconstruct the frame (and, when asked, the breakage report at full resolution).

    ``rest_parts``: a previous report's :class:`~volanim_core.reconstruct.breakage.RestParts` of the
    same attachments (made when None; the result carries them either way).
    """
    if not len(tskel):
        raise ValueError("no attached points to reconstruct: connect points to bones first")
    # neighbour lists: reconstruct() remembers them per connectivity (pose-independent)
    r = reconstruct(coarse_tskel(tskel, factor), mode=mode, source=source, kernel=kernel,
                    padding=max(1, padding // factor), progress=progress, cancel=cancel)
    out = Preview(r, factor, mode)
    if report:  # three more reconstructions: each checks ``cancel`` between its chunks
        posed_bone = r if (mode == "bone" and factor == 1) else reconstruct(tskel, mode="bone", cancel=cancel)
        if rest_parts is None:
            rest_parts = RestParts.of(tskel.connectivity, cancel)
        out.report = breakage_report(tskel, joints or {}, posed_joints or {}, posed=posed_bone, rest=rest_parts,
                                     cancel=cancel)
        out.rest_parts = rest_parts
    return out
