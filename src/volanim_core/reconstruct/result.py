"""What a reconstruction returns, whichever way it was made (engine.py's spheres, owned.py's moved voxels)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.volume import Bounds


@dataclass
class Reconstruction:
    """A reconstructed volume and what it took.

    Attributes
    ----------
    volume : (X, Y, Z) ndarray indexed ``[x, y, z]``
        uint8 (binary, mottled, bone with < 256 bones), uint16 (hotspot, bone
        with more bones) or the source's dtype (sampled).
    origin : (3,) ints
        Voxel ``[0, 0, 0]`` of ``volume`` is voxel ``origin`` of the rest frame.
    geometry : Geometry
        Where ``volume``'s voxels are in physical space: the frame's geometry shifted to ``origin``
        (what a writer records, so the posed frame overlays the scan it came from).
    stats : dict
        ``spheres``, ``filled`` (voxels), ``visits`` (voxels the spheres
        examined: the kernel's work), ``overdraw`` (visits / filled), ``clipped`` (sphere voxels outside
        given bounds), ``seconds``; hotspot adds ``hotspot_max`` and
        ``hotspot_mean`` (over covered voxels).
    """

    volume: np.ndarray
    origin: tuple[int, int, int]
    stats: dict = field(default_factory=dict)
    geometry: Geometry = IDENTITY

    @property
    def bounds(self) -> Bounds:
        lo = tuple(int(v) for v in self.origin)
        return Bounds(lo, tuple(lo[i] + self.volume.shape[i] - 1 for i in range(3)))
