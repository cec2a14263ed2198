"""Where a sampled reconstruction reads its source: the frame's grid against the source's.

    frame (tskel.geometry) --source_geometry_for--> the grid its indices are on
          --check_source_overlap--> refused when the rest points miss the source
          --Geometry.index_map--> engine: output voxel -> rest voxel -> source voxel

Before geometry was recorded, a scan with an origin reconstructed to nothing, silently: the
source's origin (millimetres) was rounded and used as a voxel offset. These two functions are the
whole rule, shared by ``reconstruct`` and ``sequence`` on the command line and in the library.
"""

from __future__ import annotations

import numpy as np

from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.rig.connectivity import Connectivity


def source_geometry_for(frame: Geometry, source: Geometry) -> tuple[Geometry, str | None]:
    """The grid a frame's voxel indices are on, given the source it samples: ``(geometry, note)``.

    A frame that records its geometry is placed by it. One that records none (files from before
    geometry was recorded) is on its source's grid -- what the tools that made it used -- except
    where the source's voxels are unit cubes along the axes: there its origin, a whole-voxel offset
    (a cropped source, a reconstruction used as a source), is applied as it always was.
    """
    if not frame.is_identity:
        return frame, None
    if source.spacing == (1.0, 1.0, 1.0) and source.direction == IDENTITY.direction:
        return frame, None
    return source, ("the frame records no geometry: it is taken to be on the source's voxel grid "
                    f"({source.describe()})")


def check_source_overlap(frame: Connectivity, source_shape, source_geometry: Geometry | None) -> None:
    """Refuse a sampled reconstruction whose rest points mostly miss the source (it would read 0s):
    the frame and the source are then in different places, and the message says both."""
    if not len(frame):
        return
    to_source = np.eye(4) if source_geometry is None else frame.geometry.index_map(source_geometry)
    idx = frame.points @ to_source[:3, :3] + to_source[3, :3]
    inside = np.all((idx > -0.5) & (idx < np.asarray(source_shape[:3]) - 0.5), axis=1)
    if inside.mean() < 0.5:
        where = source_geometry or frame.geometry
        raise ValueError(f"only {inside.mean():.0%} of the frame's rest points fall inside the source volume, "
                         f"so the sampled volume would be mostly empty; the frame's grid: "
                         f"{frame.geometry.describe()}; the source: {where.describe()}, "
                         f"{'x'.join(str(n) for n in source_shape[:3])} voxels")

