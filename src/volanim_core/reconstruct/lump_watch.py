"""Which frames of a clip can carry a lump, without reconstructing them; the report's own test on those that can.

    once (rest):   RestParts (each rest voxel's bone), each bone's reach and limb (lumps.py)
                   --> the foreign voxels: a bone's rest voxels beyond its reach and within another's (the
                       host: the flesh a lump would be made of), and who carries each
    per frame:     each foreign voxel moved by its carrier and by its host
                   --> carried off: both more than MOVED from where it lay and from where its host keeps it
                   --> a candidate when one carrier carries off SHARE of its limb (and MIN_VOXELS) or more
    candidates:    the full-resolution bone reconstruction --lumps.find_lumps--> the report's lumps

Why: a lump (lumps.py) is made of voxels whose rest point lies beyond their bone's reach, within another's,
moved away from both; every test but the last two (no other bone's own flesh lands there; the piece, opened,
is SHARE of the limb) depends only on the rest voxel and two matrices. Those counted over the rest voxels
bound what the report can find, so a frame under the bar has no lump, and a clip's scan reconstructs only the
frames over it (#84: `volanim scan` said "0 broken" over the walk while frame 644's report listed three lumps).
With ownership (the default) the posed voxels are the rest voxels moved by their owners, so the bound holds
voxel for voxel; for the thesis's spheres a posed voxel's rest point is one of its bone's spheres', which the
rest reconstruction gives to the first bone that claims it, so the bar is halved there to stay on the safe side.
"""

from __future__ import annotations

import numpy as np

from volanim_core.reconstruct.breakage import RestParts
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.reconstruct.lumps import MIN_VOXELS, MOVED, SHARE, bone_reach, frame_lumps, limb_voxels
from volanim_core.rig.nearest import segment_distances
from volanim_core.rig.skinning import segment_distance


class LumpWatch:
    """The rest pose's foreign voxels of a rigid-jointed connectivity, and :meth:`lumps` per frame."""

    def __init__(self, conn, rest: RestParts | None = None):
        self.conn = conn
        self.rest = rest or RestParts.of(conn)
        segments = [(b.proximal, b.distal) for b in conn.bones]
        voxels, bone = self.rest.voxels
        if self.rest.reach is None:
            self.rest.reach = bone_reach(segments, voxels, bone), limb_voxels(segments, bone)
        reach, limbs = self.rest.reach
        beyond = np.zeros(len(bone), bool)
        for b, (p0, p1) in enumerate(segments):
            mine = bone == b
            beyond[mine] = segment_distance(voxels[mine].astype(np.float64), p0, p1) > reach[b]
        at = np.flatnonzero(beyond)
        d = segment_distances(voxels[at].astype(np.float64), np.array([[p0, p1] for p0, p1 in segments], np.float64))
        inside = d <= reach[None, :]
        keep = inside.any(axis=1)
        self.points = voxels[at[keep]].astype(np.float64)
        self.carrier = bone[at[keep]].astype(np.int64)
        self.host = np.argmin(np.where(inside[keep], d[keep], np.inf), axis=1)
        owned = conn.ownership is not None
        self.bar = np.maximum(SHARE * limbs, MIN_VOXELS) * (1.0 if owned else 0.5)

    def may_carry(self, matrices: np.ndarray) -> bool:
        """Whether the frame posed by ``matrices`` can carry a lump the report would flag (False: it cannot)."""
        if not len(self.points):
            return False
        m = np.asarray(matrices, np.float64)
        p = self.points
        carried = np.einsum("ki,kij->kj", p, m[self.carrier, :3, :3]) + m[self.carrier, 3, :3]
        kept = np.einsum("ki,kij->kj", p, m[self.host, :3, :3]) + m[self.host, 3, :3]
        off = (np.linalg.norm(carried - p, axis=1) > MOVED) & (np.linalg.norm(carried - kept, axis=1) > MOVED)
        counts = np.bincount(self.carrier[off], minlength=len(self.bar))
        return bool((counts >= self.bar).any())

    def lumps(self, matrices: np.ndarray, joints: dict) -> list:
        """The report's lumps of the frame (largest first), reconstructed only when :meth:`may_carry`;
        ``joints``: the posed joints, to name each lump's place."""
        if not self.may_carry(matrices):
            return []
        tskel = self.conn.posed(np.asarray(matrices, np.float64))
        return frame_lumps(tskel, reconstruct(tskel, mode="bone"), self.rest, joints)
