"""A sequence on disk: an OME-Zarr time series plus an append-only manifest of finished frames.

    OUT.zarr/zarr.json            group; attributes "ome" (NGFF 0.5 multiscales: t, z, y, x) and "volanim"
    OUT.zarr/0/                   the array (T, Z, Y, X); 128^3 chunks inside shards (1, Z, Y, X): one shard
                                  per frame, so no two tasks ever write the same shard (concurrent writes
                                  into one shard silently lose data); chunks outside the box a frame's
                                  body reaches are never written (a walk's shared grid is mostly empty)
    OUT.zarr/volanim-plan.json    what was asked (the plan's key), written once, atomically
    OUT.zarr/volanim-frames.jsonl one line per finished frame: index, number, sha256 of its bytes and the
                                  region it hashed (z, y, x), stats

This module writes; reading goes through :mod:`~volanim_core.sequence.checked` (``read_store``), which
checks this metadata once and verifies each frame against its sha256.

A task's frames are appended to the manifest only after their shards are
written, by the one process that runs the sequence, in one ``write`` +
``fsync``; a killed run leaves at most a torn last line, which reading
ignores. So a rerun skips exactly the frames that were complete and redoes the rest.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np

PLAN_FILE, FRAMES_FILE = "volanim-plan.json", "volanim-frames.jsonl"


def frame_checksum(part_zyx: np.ndarray, region=None) -> str:
    """sha256 of a frame: the part its body reaches (and where that is); the rest is zero by construction."""
    # plain ints: NumPy 2 writes np.int64(3) where Python writes 3, and a reader's slices are Python's
    h = hashlib.sha256(repr([(int(s.start), int(s.stop)) for s in region or ()]).encode())
    h.update(np.ascontiguousarray(part_zyx).data)
    return h.hexdigest()


def frame_record(index: int, number: int, part_zyx: np.ndarray, region=None, **stats) -> dict:
    """The manifest record of frame ``index`` whose ``part_zyx`` was written at ``region`` (``[z, y, x]``
    slices; default: the whole frame): its checksum and the region it covers, which a reader verifies."""
    region = region or tuple(slice(0, n) for n in part_zyx.shape)
    return {"index": int(index), "number": int(number), "sha256": frame_checksum(part_zyx, region),
            "region": [[int(s.start), int(s.stop)] for s in region], **stats}


# 128, not 64: zarr spends ~0.4 ms per chunk written, whatever its size -- a frog frame's 168 chunks
# of 64^3 cost 4x its 21 of 128^3 (measured: 78 vs 34 ms a frame), for 7 % more bytes on disk
CHUNK_EDGE = 128
# Every chunk of the box a task writes is stored, zeros included: zarr's check for an all-zero
# chunk (write_empty_chunks=False) took more than half of a frame's write (np.array_equal per
# chunk), and the box is already the part of the grid a body reaches, so few of its chunks are empty.
WRITE_CONFIG = {"write_empty_chunks": True}


def chunk_shape(shape_zyx, edge: int = CHUNK_EDGE) -> tuple[int, int, int]:
    """Bricks of ``edge`` voxels (fewer along a shorter axis): a posed body fills a small part of a
    sequence's shared grid, and bricks it does not reach are never written."""
    return tuple(int(max(1, min(n, edge))) for n in shape_zyx)


def create(path: str | Path, shape_zyx, n_frames: int, dtype, origin_xyz, plan: dict, *, fps: float = 24.0,
           geometry=None, palette=None):
    """A new, empty sequence store (an existing one at ``path`` is replaced).

    ``origin_xyz``: the grid's voxel ``[0, 0, 0]`` in the frames' voxel indices; ``geometry``: where it
    is in physical space (default: the identity shifted to ``origin_xyz``). ``palette``: a colour
    sequence's ``(256, 3)`` colours, one per index its frames hold (:mod:`volanim_core.colour.indexed`).
    OME-Zarr's ``scale`` and ``translation`` are physical (millimetres, :func:`ome_scale`), so napari
    overlays a frame on its scan, reversed axes included; OME-Zarr has no rotation, so a scan with
    swapped or tilted axes has its full geometry in volanim's attributes only.
    """
    import shutil

    import zarr

    from volanim_core.geometry import Geometry
    from volanim_core.io.atomic import atomic_write_text, clean_stale, pending_name

    final = Path(path)
    # made whole beside the target, then renamed: a run killed while creating its store leaves no half-made
    # folder that the rerun must refuse as "not a volanim sequence" (#64), only a temporary the next sweeps
    final.parent.mkdir(parents=True, exist_ok=True)
    clean_stale(final.parent, final.name)
    path = final.parent / pending_name(final.name)
    dtype = np.dtype(dtype)
    z, y, x = (int(v) for v in shape_zyx)
    ox, oy, oz = (float(v) for v in origin_xyz)
    if geometry is None:
        geometry = Geometry(origin=(ox, oy, oz))
    (sx, sy, sz), _ = ome_scale(geometry)
    px, py, pz = geometry.origin
    ome = {"version": "0.5", "multiscales": [{
        "name": final.stem,
        "axes": [{"name": "t", "type": "time", "unit": "second"}, {"name": "z", "type": "space", "unit": "millimeter"},
                 {"name": "y", "type": "space", "unit": "millimeter"},
                 {"name": "x", "type": "space", "unit": "millimeter"}],
        "datasets": [{"path": "0", "coordinateTransformations": [
            {"type": "scale", "scale": [1.0 / fps, sz, sy, sx]},
            {"type": "translation", "translation": [0.0, pz, py, px]}]}],
    }]}
    root = zarr.open_group(str(path), mode="w", zarr_format=3)
    root.attrs.update({"ome": ome, "volanim": {"origin_xyz": [ox, oy, oz], "mode": plan.get("mode"),
                                               "frames": plan.get("numbers"), "geometry": geometry.header_value()}})
    if palette is not None:
        root.attrs["volanim"] = {**root.attrs["volanim"], "palette": np.asarray(palette, np.uint8).tolist()}
    chunks = chunk_shape((z, y, x))
    # a shard holds whole chunks: round it up (past the array's edge), still exactly one per frame
    shard = tuple(-(-n // c) * c for n, c in zip((z, y, x), chunks))
    root.create_array("0", shape=(n_frames, z, y, x), dtype=dtype, chunks=(1, *chunks), shards=(1, *shard),
                      fill_value=0, dimension_names=("t", "z", "y", "x"), config=WRITE_CONFIG)
    atomic_write_text(path / PLAN_FILE, json.dumps(plan, indent=1))
    (path / FRAMES_FILE).write_bytes(b"")
    if final.exists():  # a store of another plan the caller chose to replace (never anything else)
        shutil.rmtree(final) if final.is_dir() else final.unlink()
    os.replace(path, final)


def ome_scale(geometry) -> tuple[tuple[float, float, float], bool]:
    """OME-Zarr's per-axis ``scale`` (x, y, z) for a grid, and whether scale and translation place it exactly.

    OME-Zarr (0.5) has scale and translation, no rotation: an axis that runs against its physical axis
    (a scan stored RAS, read into LPS with x and y reversed) is a negative scale, which napari and
    neuroglancer draw flipped, so the frame lies on the scan; the translation stays voxel ``[0, 0, 0]``'s
    centre. Axes swapped or tilted (a sagittal acquisition, an oblique one) no scale can say: the
    spacing is written and ``False`` returned (the full geometry is in volanim's attributes).
    """
    d = geometry.matrix
    signs = np.sign(np.diag(d))
    exact = bool(np.allclose(d, np.diag(signs), atol=1e-6) and np.all(signs != 0))
    spacing = np.asarray(geometry.spacing, np.float64)
    return tuple(float(v) for v in (spacing * signs if exact else spacing)), exact


def read_plan(path: str | Path) -> dict | None:
    """The plan of the store at ``path``, or None when there is none or it is not a plan (a rerun replaces it)."""
    from volanim_core.errors import FormatError
    from volanim_core.io.files import load_json

    p = Path(path) / PLAN_FILE
    if not p.is_file():
        return None
    try:
        plan = load_json(p, what="sequence plan")
    except FormatError:
        return None
    return plan if isinstance(plan, dict) else None


def finished(path: str | Path) -> dict[int, dict]:
    """Frame index -> its manifest record, for every frame recorded complete (a torn last line is ignored)."""
    p = Path(path) / FRAMES_FILE
    out: dict[int, dict] = {}
    if not p.is_file():
        return out
    for line in p.read_bytes().split(b"\n"):
        try:
            rec = json.loads(line)
            out[int(rec["index"])] = rec
        except (ValueError, KeyError, TypeError):
            continue  # the line a kill cut short
    return out


def bytes_on_disk(path: str | Path) -> int:
    """What a store (or one of its folders, e.g. ``0`` for the frames alone) takes on disk, in bytes."""
    return sum(f.stat().st_size for f in Path(path).rglob("*") if f.is_file())


def record(path: str | Path, *recs: dict) -> None:
    """Append finished frames (a task's): one write, then one fsync (called by the driver only)."""
    line = b"".join((json.dumps(rec, separators=(",", ":")) + "\n").encode() for rec in recs)
    fd = os.open(Path(path) / FRAMES_FILE, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
    try:
        os.write(fd, line)
        os.fsync(fd)
    finally:
        os.close(fd)


def open_frames(path: str | Path, mode: str = "r"):
    """The ``(T, Z, Y, X)`` zarr array of a sequence."""
    import zarr

    array = zarr.open_array(str(Path(path) / "0"), mode=mode)
    return array if mode == "r" else array.with_config(WRITE_CONFIG)  # runtime config: not kept in the store

