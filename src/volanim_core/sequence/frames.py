"""What a sequence is made of: one pose per frame for one connectivity, from any source.

    .trans files          the matrices, checked against the .connect's bones
    .tskel files          the matrices; its points must be the .connect's (else refused)
    a clip (.bvh, glTF)   retargeted onto --bones (optionally --map, --animation), --frames START:STOP:STEP
    effects after them    melt, teleport, crumble (``effects.py``)

Each frame is a :class:`FrameSpec`: a number (for file names and the manifest),
the bone matrices, a DT scale (1 except in melts: one number, or one per point)
and how far the crumble has fallen (0 except in crumbles).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io.frame_files import check_complete, frame_number
from volanim_core.rig.connectivity import Connectivity, Tskel
from volanim_core.rig.tskel_tools import check_root_order


@dataclass(frozen=True)
class FrameSpec:
    number: int
    matrices: np.ndarray  # (B, 4, 4) row-vector, rest voxel coordinates -> posed
    dt_scale: float | np.ndarray = 1.0  # every DT times this (a number, or one per point)
    crumble: float = 0.0  # 0: standing; 1: every voxel has fallen onto the heap
    down: str = "-z"  # the way voxels fall in a crumble
    heap: str = "keep"  # a crumble heap's values: each grain's own, or the capped sum resting on it
    floor: int | None = None  # a crumble's floor (voxel index along its axis); None: the body's lowest voxel
    drop: float | None = None  # how far a crumble's voxels have fallen; None: from ``crumble`` and the height

    def tskel(self, conn: Connectivity) -> Tskel:
        plain = np.isscalar(self.dt_scale) and self.dt_scale == 1.0
        if plain:
            return conn.posed(self.matrices)
        dt = conn.dt * np.asarray(self.dt_scale, np.float64)
        skin = conn.skin if conn.joints.smooth else None  # blend as the unscaled body does
        return Tskel(conn.bones, self.matrices, conn.points, dt, conn.thinness, conn.bone, conn.metric, conn.geometry,
                     joints=conn.joints, skin=skin)

    def key(self) -> bytes:
        """Everything that decides this frame's voxels besides the connectivity (for plan keys)."""
        fall = (self.crumble, self.down)
        if (self.heap, self.floor, self.drop) != ("keep", None, None):  # older stores' keys stay as they were
            fall += (self.heap, self.floor, self.drop)
        return b"|".join([np.ascontiguousarray(self.matrices).tobytes(), str(self.number).encode(),
                          np.asarray(self.dt_scale, np.float64).tobytes(), repr(fall).encode()])


def frames_from_files(conn: Connectivity, paths, *, bones=None, mapping=None, frames=slice(None),
                      up: str = "auto", forward: str = "auto", check: bool = True,
                      animation: str | None = None) -> list[FrameSpec]:
    """FrameSpecs from ``.trans``/``.tskel`` files or one clip (``.bvh``, glTF: needs ``bones``, a
    BoneSkeleton; ``animation`` picks one of a glTF file's)."""
    from volanim_core import io
    from volanim_core.io.clip_files import is_clip

    paths = [Path(p) for p in paths]
    if not paths:
        raise ValueError("no frames given: name .trans or .tskel files, or a clip (.bvh, .glb, .gltf)")
    if any(is_clip(p) for p in paths):
        if len(paths) != 1:
            raise ValueError("give one clip (.bvh, .glb, .gltf), or .trans/.tskel files, not both")
        return _from_clip(conn, paths[0], bones, mapping, frames, up, forward, check, animation)
    if animation is not None:
        raise ValueError("--animation picks one of a glTF clip's animations; these frames are .trans/.tskel files")
    check_complete(paths)
    numbers = [frame_number(p) for p in paths]
    if None in numbers or len(set(numbers)) != len(numbers):
        numbers = list(range(len(paths)))  # names without (distinct) numbers: their order on the command line
    out = []
    for p, n in sorted(zip(paths, numbers), key=lambda pn: pn[1]):
        suffix = p.suffix.lower()
        if suffix == ".trans":
            trans = io.read_trans(p).on_grid(conn.geometry)
            mats, bones_of = trans.matrices, trans.bones
        elif suffix == ".tskel":
            t = io.read_tskel(p)
            same = len(t) == len(conn) and np.array_equal(t.points, conn.points) and np.array_equal(t.bone, conn.bone)
            if not same:
                raise FormatError(p, f"its {len(t)} points are not the .connect's {len(conn)}: a sequence runs "
                                     "one connectivity; pass the .trans frames (or the matching .connect)")
            mats, bones_of = t.matrices, t.bones
        else:
            raise ValueError(f"{p}: a frame must be a .trans or .tskel file, or a clip (.bvh, .glb, .gltf, .vrma)")
        try:
            check_root_order(conn.bones, bones_of, p.name)
        except ValueError as exc:
            raise FormatError(p, str(exc)) from None
        out.append(FrameSpec(int(n), np.asarray(mats, np.float64)))
    return out


def _from_clip(conn, path: Path, bones, mapping, frames, up, forward, check, animation) -> list[FrameSpec]:
    from volanim_core.io.clip_files import read_clip
    from volanim_core.motion.retarget import Retarget, check_mapping_file
    from volanim_core.rig.pose import root_bones

    if bones is None:
        raise ValueError(f"{path.name}: a clip needs the bone skeleton it drives (--bones MODEL.bones)")
    bones = bones.on_grid(conn.geometry)  # bones drawn on another grid land where they were drawn
    check_root_order(conn.bones, root_bones(bones), ".bones")
    motion = read_clip(path, animation)
    if mapping is not None:
        check_mapping_file(path, mapping, bones, motion)
    retarget = Retarget.build(bones, motion, mapping, up=up, forward=forward)
    if check:  # as bvh2trans: a quadruped's clip or one lying down is refused before any frame is made
        from volanim_core.motion.plausible import check_clip, refuse_failed

        refuse_failed(path, check_clip(retarget)[0])
    mats = retarget.matrices(frames)
    numbers = list(range(motion.frames))[frames]
    if not numbers:
        raise ValueError(f"{path.name}: the frame range selects none of its {motion.frames} frames")
    return [FrameSpec(n, m) for n, m in zip(numbers, mats)]

