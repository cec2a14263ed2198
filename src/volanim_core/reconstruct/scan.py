"""Scan a whole animation for breakage: one verdict per frame, so the user jumps to the worst one.

    once:       the sphere pairs that touch at rest, the neighbour lists,
                the rest pose's pieces on the coarse grid,
                the sphere pairs that can prove a frame whole (whole.py)    (pose-independent)
    per frame:  cracks and stumps from the posed sphere centres             (no voxels: cheap)
                one piece proved from the spheres (whole.py), or else
                connected components of a ``factor``-times coarser bone reconstruction
                lumps: the report's own, at full resolution, only in the frames the rest
                pose's foreign voxels say can carry one (lump_watch.py; rigid joints)

The "once" part and the per-frame verdict are a :class:`Scanner`.

The full report (lost voxels, hotspots, detached pieces by joint) stays with
the studio's full preview of one frame; the scan only has to rank frames.
The coarse grid (the live preview's) is 8x cheaper; it may close a hairline
gap or drop a limb thinner than two voxels, so the full preview (F5) of the
frame the user jumps to is the verdict that counts.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.progress import Reporter
from volanim_core.reconstruct.breakage import components, misplaced_points, stumps
from volanim_core.reconstruct.cracks import cracks, touching_pairs
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.reconstruct.lump_watch import LumpWatch
from volanim_core.reconstruct.whole import WholeProof
from volanim_core.rig.connectivity import Connectivity
from volanim_core.rig.tskel_tools import coarse_tskel, identity_tskel


@dataclass(frozen=True)
class FrameVerdict:
    frame: int
    pieces: int  # connected components of the posed volume (1: whole)
    detached: int  # voxels (full-resolution estimate) outside the largest piece
    cracks: int  # sphere pairs of different bones that touched at rest and part here
    gap: float  # their summed opening, voxels
    worst_joint: str  # the joint nearest the widest cracks ('' when none)
    stump: int = 0  # points left behind along another bone (breakage.stumps), summed
    rest_pieces: int = 1  # pieces of the rest pose on the same coarse grid: only more than these is breakage
    lump: int = 0  # voxels of the largest lump (lumps.py, at full resolution: the report's), 0 when none
    lump_near: str = ""  # the posed joint nearest it

    @property
    def healthy(self) -> bool:
        """Not :attr:`broken`: one rule, said the same way by ``volanim scan``, the studio's scan and a
        frame's report (#61: the studio counted a frame with cracks alone as unhealthy, the command did not)."""
        return not self.broken

    @property
    def broken(self) -> bool:
        """A piece torn off or a stump left behind: what the report calls broken (cracks alone open at
        every bent joint and are no verdict)."""
        return self.pieces > self.rest_pieces or self.stump > 0

    def badness(self) -> tuple:
        """Sort key, worst first: detached pieces outrank stumps, stumps outrank lumps, lumps outrank cracks,
        then how much."""
        return (-min(max(self.pieces - self.rest_pieces, 0), 1), -self.detached, -min(self.stump, 1), -self.stump,
                -min(self.lump, 1), -self.lump, -self.gap)


class Scanner:
    """What a scan makes once (pose-independent: the rest pose's pieces, the sphere pairs that touch at rest,
    the points already misplaced, the joints to name, the pairs that prove a frame whole), then one
    :meth:`verdict` per frame."""

    def __init__(self, conn: Connectivity, joints: dict | None = None, factor: int = 2):
        from scipy.spatial import cKDTree

        self.conn, self.joints, self.factor = conn, dict(joints or {}), factor
        rest = identity_tskel(conn)
        coarse = coarse_tskel(rest, factor)
        # a body in several pieces at rest (the frog's specks) is not broken by a pose that keeps them
        self.rest_pieces = max(len(components(reconstruct(coarse, mode="bone", padding=1).volume)), 1)
        # a frame proved whole from its spheres needs no voxels (whole.py): most frames of a clip
        self.whole = WholeProof(coarse) if self.rest_pieces == 1 else None
        self.pairs = touching_pairs(rest)
        self.misplaced = misplaced_points(rest)  # none on an owned body (moved by its ownership)
        self.names = list(self.joints)
        self.near = cKDTree(np.array([self.joints[n] for n in self.names], np.float64)) if self.names else None
        # lumps as the report finds them, at full resolution, in the frames that can carry one (lump_watch.py)
        self.watch = None if conn.joints.smooth else LumpWatch(conn)
        self.moved_by = [_joint_bone(conn, self.joints[n]) for n in self.names]

    def verdict(self, frame: int, mats: np.ndarray) -> FrameVerdict:
        posed = self.conn.posed(np.asarray(mats))
        where, gaps = cracks(posed, pairs=self.pairs)
        worst = ""
        if len(gaps) and self.near is not None:
            _, k = self.near.query(where)
            worst = self.names[int(np.bincount(k, weights=gaps, minlength=len(self.names)).argmax())]
        coarse = coarse_tskel(posed, self.factor)
        if self.whole is not None and self.whole.proves(coarse):
            sizes = [0]  # one piece (its size is not needed: nothing is detached)
        else:
            sizes = components(reconstruct(coarse, mode="bone", padding=1).volume)
        behind = stumps(posed, self.joints, self.misplaced)
        lumps = [] if self.watch is None else self.watch.lumps(mats, self.posed_joints(mats))
        return FrameVerdict(frame, len(sizes), int(sum(sizes[self.rest_pieces:])) * self.factor ** 3, len(gaps),
                            float(gaps.sum()), worst or (behind[0].joint if behind else ""),
                            sum(b.points for b in behind), self.rest_pieces,
                            lumps[0].voxels if lumps else 0, lumps[0].near if lumps else "")

    def posed_joints(self, mats: np.ndarray) -> dict:
        """Each named joint moved by the bone it belongs to (to name a lump's place)."""
        m = np.asarray(mats, np.float64)
        return {n: (np.asarray(self.joints[n], np.float64) @ m[b, :3, :3] + m[b, 3, :3]) if b >= 0 else
                np.asarray(self.joints[n], np.float64) for n, b in zip(self.names, self.moved_by)}


def _joint_bone(conn: Connectivity, p) -> int:
    """The first bone (root order) that starts at joint ``p``, else one that ends there, else -1."""
    for end in ("proximal", "distal"):
        for b, seg in enumerate(conn.bones):
            if np.allclose(getattr(seg, end), p, atol=1e-6):
                return b
    return -1


def scan_frames(conn: Connectivity, matrices: np.ndarray, frames=None, *, joints: dict | None = None,
                factor: int = 2, progress=None, cancel=None) -> list[FrameVerdict]:
    """One :class:`FrameVerdict` per frame of ``matrices`` (``(F, B, 4, 4)``); ``frames`` numbers them."""
    frames = list(range(len(matrices))) if frames is None else [int(f) for f in frames]
    report = Reporter(progress, cancel)
    scanner = Scanner(conn, joints, factor)
    out = []
    for n, (frame, mats) in enumerate(zip(frames, matrices)):
        report(n, len(frames))
        out.append(scanner.verdict(frame, mats))
    report(len(frames), len(frames))
    return out


def scan_summary(verdicts: list[FrameVerdict]) -> str:
    """The one sentence ``volanim scan`` and the studio's scan both open with."""
    broken = sum(v.broken for v in verdicts)
    return (f"{len(verdicts)} frames scanned: {broken} broken (a piece torn off or a stump left behind), "
            f"{sum(v.lump > 0 for v in verdicts)} with lumps, {sum(v.cracks > 0 for v in verdicts)} with cracks")


def worst_first(verdicts: list[FrameVerdict]) -> list[FrameVerdict]:
    return sorted(verdicts, key=lambda v: (*v.badness(), v.frame))
