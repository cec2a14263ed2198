"""Run a sequence: plan one grid for every frame, skip what is done, reconstruct the rest anywhere.

    frames --shared bounds (tskelbounds over all frames + padding)--> one grid, one origin
    plan key (connectivity, frames, mode, kernel, padding, source) --> new store, or resume the old one
    a colour source --colour.indexed--> palette indices (sequenced) + the palette (in the store's attributes)
    frames not in the manifest --executor.submit(reconstruct_frames)--> stats --> manifest (driver only)

The executor (``volanim_core.parallel``) is this process (1 worker), a local
process pool (N workers, one numba thread each) or a Dask cluster's
``client.get_executor()`` -- the same task function runs in all three, so a
frame is bit-identical wherever it was made.
"""

from __future__ import annotations

import hashlib
import time
from concurrent.futures import Future
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.colour.indexed import index_colours
from volanim_core.io.atomic import naming_the_output
from volanim_core.io.files import resolved
from volanim_core.limits import available_bytes, human_bytes
from volanim_core.parallel import THIS_PROCESS, RunOn, executor, wait_some
from volanim_core.reconstruct.engine import check_output_grid, grid_bounds, output_dtype
from volanim_core.rig.connectivity import Connectivity
from volanim_core.volume import Bounds

from . import store
from .frames import FrameSpec
from .task import Payload, check_frame_pattern, install, reconstruct_frames


@dataclass
class SequenceReport:
    bounds: Bounds
    dtype: str
    records: list[dict]  # per frame (index order): the manifest record
    skipped: int  # frames already complete, not redone
    computed: int
    seconds: float
    rest_filled: int  # the rest pose's filled voxels in the same mode (for loss)
    workers: str = ""
    colours: str = ""  # a colour source: its palette (how many colours, exact or the quantisation's error)


MAX_PADDING = 256  # voxels around the bodies; 10^4 made a grid of terabytes before anything refused it


def shared_bounds(conn: Connectivity, frames: list[FrameSpec], padding: int = 2,
                  boxes: list[Bounds] | None = None) -> Bounds:
    """One output grid holding every frame (the old ``tskelbounds`` over all of them), and room
    on the floor for a crumble's heap. ``boxes``: the frames' :func:`frame_boxes`, when made already."""
    boxes = frame_boxes(conn, frames) if boxes is None else boxes
    # the union of the unpadded boxes, padded: exactly grid_bounds(every frame, padding)
    bounds = Bounds(tuple(min(b.lo[a] for b in boxes) - padding for a in range(3)),
                    tuple(max(b.hi[a] for b in boxes) + padding for a in range(3)))
    crumbles = [f for f in frames if f.crumble]
    if crumbles:
        room = heap_room(conn, crumbles[0], padding)
        bounds = Bounds(tuple(map(min, bounds.lo, room.lo)), tuple(map(max, bounds.hi, room.hi)))
    return bounds


def frame_boxes(conn: Connectivity, frames: list[FrameSpec]) -> list[Bounds]:
    """Each frame's posed spheres' bounding box, unpadded: the part of the grid the frame can fill."""
    return [grid_bounds(f.tskel(conn), 0) for f in frames]


def frame_grids(frames: list[FrameSpec], boxes: list[Bounds], bounds: Bounds) -> list[Bounds]:
    """The grid each frame is reconstructed in: its box inside the shared grid (a voxel's value depends
    only on the spheres covering it, so that is the shared grid's frame cut out; a walk's grid is 5x
    its body's box), or the whole grid for a crumble, whose heap falls to the floor."""
    return [bounds if f.crumble else Bounds(tuple(map(max, b.lo, bounds.lo)), tuple(map(min, b.hi, bounds.hi)))
            for f, b in zip(frames, boxes)]


def heap_room(conn: Connectivity, spec: FrameSpec, padding: int) -> Bounds:
    """The pose's box widened sideways to hold the heap its voxels make: a 45-degree pile of
    ``V`` voxels on 4-neighbour columns is a square pyramid of height ``(1.5 V)**(1/3)`` and
    as wide each side of its centre (``V`` from the rest pose; the grid's sides are walls,
    so a heap that is a little larger leans on them, nothing is lost)."""
    from .effects import parse_axis

    box = grid_bounds(spec.tskel(conn), padding)
    reach = int(np.ceil((1.5 * _rest_filled(conn)) ** (1 / 3))) + padding
    axis, _ = parse_axis(spec.down)
    lo, hi = list(box.lo), list(box.hi)
    for a in range(3):
        if a != axis:
            mid = (box.lo[a] + box.hi[a]) // 2
            lo[a], hi[a] = min(lo[a], mid - reach), max(hi[a], mid + reach)
    return Bounds(tuple(lo), tuple(hi))


def plan_key(conn: Connectivity, frames: list[FrameSpec], mode: str, kernel: int, padding: int, source,
             source_geometry=None) -> str:
    """What the store's content depends on; a rerun with another key must not resume."""
    h = hashlib.blake2b(digest_size=16)
    for a in (conn.points, conn.dt, conn.bone, *[np.asarray(b.proximal + b.distal) for b in conn.bones]):
        h.update(np.ascontiguousarray(a).tobytes())
    for f in frames:
        h.update(f.key())
    h.update(f"{mode}|{kernel}|{padding}|{conn.metric}".encode())
    if not conn.geometry.is_identity:  # keys of stores made before geometry was recorded stay the same
        h.update(conn.geometry.header_value().encode())
    if conn.joints.smooth:  # likewise for stores made before smooth joints
        # "thin": a stretched sheet's spheres thin (rig/skinning.posed_radii); a store made before they did
        # holds other voxels and is not resumed
        h.update(f"joints {conn.joints.text()} thin".encode())
    if source_geometry is not None and not source_geometry.is_identity:
        h.update(source_geometry.header_value().encode())
    if source is not None:
        h.update(str((source.shape, source.dtype.str)).encode())
        h.update(np.ascontiguousarray(source).data)
    return h.hexdigest()


def check_memory(bounds: Bounds, dtype: np.dtype, workers: int, source) -> int:
    """Bytes the frame grid ``bounds`` needs (give the largest); refuse (ValueError) when ``workers`` of
    them cannot fit, saying how large."""
    voxels = int(np.prod(bounds.shape, dtype=np.int64))
    per_frame = voxels * (2 * dtype.itemsize + 4)  # output + stencil (float32) + the copy written out
    check_output_grid(bounds.shape, 2 * dtype.itemsize + 4)  # the voxel limit, and one frame at all
    source_bytes = 0 if source is None else int(source.nbytes)
    need = workers * (per_frame + source_bytes)
    free = available_bytes()
    if free is not None and need > free:
        grid = "x".join(map(str, bounds.shape))
        raise ValueError(f"each frame needs {human_bytes(per_frame)} (grid {grid} = {voxels:,} voxels of "
                         f"{dtype}) plus the source ({human_bytes(source_bytes)}) per worker: {workers} workers "
                         f"need {human_bytes(need)} but {human_bytes(free)} is available; use fewer --workers "
                         f"or a smaller --padding")
    return per_frame


@dataclass(frozen=True)
class SequenceSettings:
    """What every frame of a sequence is: reconstructed in ``mode`` (``sampled`` reads ``source``, whose voxels
    lie where ``source_geometry`` says, through a ``kernel``), on one grid ``padding`` voxels round every
    body, at ``fps``; ``every_frame_as``: each frame also written as a volume (``frame.%04d.vti``).
    ``volanim sequence``'s options of the same names."""

    mode: str = "binary"
    source: np.ndarray | None = None
    source_geometry: object = None  # a volanim_core.geometry.Geometry
    kernel: int = 1
    padding: int = 2
    fps: float = 24.0
    every_frame_as: str | None = None


EXISTING = ("resume", "replace-other", "redo")


def run_sequence(conn: Connectivity, frames: list[FrameSpec], out, settings: SequenceSettings = SequenceSettings(),
                 *, on: RunOn = THIS_PROCESS, existing: str = "resume", on_frame=None,
                 frame_seconds=None, cancel=None, on_palette=None) -> SequenceReport:
    """Reconstruct ``frames`` into the OME-Zarr store ``out``; see the module docstring.

    The store records the frames' geometry (``conn.geometry`` at the shared grid's origin) in physical units.
    ``existing``: what a store already at ``out`` gets. ``resume`` (default): the same sequence's finished
    frames are kept and the rest made; another sequence there is refused. ``replace-other``: the same, but
    another sequence is replaced (a cache, like the studio's movie). ``redo`` (``--force``): made again.
    ``on_frame(record, done, total)`` after each finished frame (progress); ``on_palette(done, total)`` while
    a colour source is indexed, before any frame (a second on a colour mannequin: a bar that moves).
    ``cancel()``: asked while frames are being made, not only when one finishes (Cancelled when it says so).
    ``frame_seconds(record) -> float``: what a finished frame cost, for sizing Dask's tasks
    (``frames_per_task``); default the ``seconds`` its worker measured. The frames never depend on
    it; a test passes a constant, so the tasks are known whatever the machine's load.
    """
    if not frames:
        raise ValueError("no frames to reconstruct")
    if existing not in EXISTING:
        raise ValueError(f"existing must be one of {', '.join(EXISTING)}, got {existing!r}")
    mode, source, source_geometry, kernel = settings.mode, settings.source, settings.source_geometry, settings.kernel
    padding, fps, every_frame_as = settings.padding, settings.fps, settings.every_frame_as
    workers, scheduler, threads_per_worker = on.workers, on.scheduler, on.threads_per_worker
    force, replace_other = existing == "redo", existing == "replace-other"
    for name, value in (("workers", workers), ("threads per worker", threads_per_worker)):
        if value is not None and value < 1:
            raise ValueError(f"{name} must be 1 or more, got {value}")
    if not 0 < fps <= 1000:
        raise ValueError(f"fps must be above 0 and at most 1000, got {fps:g}")
    if every_frame_as:
        check_frame_pattern(every_frame_as)
    if mode == "sampled" and source is None:
        raise ValueError("sampled mode needs the source volume (--source)")
    palette, colours = None, ""
    if source is not None and np.ndim(source) == 4:  # colour: indices sequenced, the palette in the store
        if kernel != 1:
            raise ValueError(f"a colour source is sequenced as palette indices, read at the nearest voxel "
                             f"(kernel 1): indices cannot be averaged, got kernel {kernel}")
        indexed = index_colours(source, progress=on_palette, cancel=cancel)
        colours = describe_palette(indexed)
        source, palette = indexed.indices, indexed.palette
    elif source is not None and np.ndim(source) != 3:
        raise ValueError(f"a source is a grey [x, y, z] or colour [x, y, z, 3] volume, got shape {np.shape(source)}")
    if isinstance(padding, bool) or not isinstance(padding, int | np.integer) or not 0 <= padding <= MAX_PADDING:
        raise ValueError(f"padding must be a whole number of voxels 0..{MAX_PADDING}, got {padding!r}")
    t0 = time.perf_counter()
    out = Path(out)
    boxes = frame_boxes(conn, frames)  # each frame posed once, here
    bounds = shared_bounds(conn, frames, padding, boxes)
    grids = frame_grids(frames, boxes, bounds)
    dtype = output_dtype(mode, len(conn.bones), None if source is None else source.dtype)
    n_workers = workers or 1
    if scheduler is None:
        check_memory(max(grids, key=lambda g: np.prod(g.shape, dtype=np.int64)), dtype, n_workers, source)
    key = plan_key(conn, frames, mode, kernel, padding, source, source_geometry)
    if palette is not None:  # the same indices under other colours are another sequence
        key = hashlib.blake2b((key + palette.tobytes().hex()).encode(), digest_size=16).hexdigest()
    plan = {"key": key, "mode": mode, "kernel": kernel, "padding": padding, "frames": len(frames),
            "numbers": [f.number for f in frames], "bounds": [list(bounds.lo), list(bounds.hi)], "dtype": dtype.str}
    # a full disk names the store: it stopped there, and its finished frames stay for the next run
    records: dict[int, dict] = {}
    frame_bytes = int(np.prod(bounds.shape, dtype=np.int64)) * dtype.itemsize  # a frame's most, uncompressed

    def room_left() -> str:
        left = len(frames) - len(records)
        most = f"{left * frame_bytes:,} bytes ({left} frames of at most {frame_bytes:,})"
        if not records:
            return f"up to {most}"
        # a walk's frame is mostly empty and compressed: the frames on disk say what the rest will take
        each = store.bytes_on_disk(out / "0") / len(records)
        return (f"about {human_bytes(left * each)} more ({left} frames of about {human_bytes(each)}, as the "
                f"{len(records)} written; at most {most} uncompressed)")

    full_disk = naming_the_output(out, "the sequence store (its finished frames are kept: run again with room)",
                                  room_left)
    old = store.read_plan(out) if out.exists() else None
    if out.exists() and old is None and (out.is_file() or any(out.iterdir())):
        # never replaced, even with --force: it may be anything the user keeps there
        raise ValueError(f"{out} exists and is not a volanim sequence; choose another -o")
    if old is not None and old.get("key") == key and not force:
        done = store.finished(out)
        rest = int(old["rest_filled"]) if isinstance(old.get("rest_filled"), int) else _rest_filled(conn)
    else:
        if old is not None and old.get("key") != key and not (force or replace_other):
            raise ValueError(f"{out} holds another sequence (different frames, connectivity, mode or source); "
                             "pass --force to replace it, or choose another -o")
        rest = plan["rest_filled"] = _rest_filled(conn)  # once per store: a resumed run does not redo it
        with full_disk:
            store.create(out, bounds.shape[::-1], len(frames), dtype, bounds.lo, plan, fps=fps,
                         geometry=conn.geometry.shifted(bounds.lo), palette=palette)
        done = {}
    if every_frame_as:
        Path(every_frame_as).parent.mkdir(parents=True, exist_ok=True)
    todo = [i for i in range(len(frames)) if i not in done]
    payload = Payload(conn, mode, kernel, bounds, str(resolved(out)), source, source_geometry, every_frame_as,
                      threads_per_worker)
    records.update(done)
    total = len(frames)
    task_seconds = DASK_TASK_SECONDS if scheduler is not None else 0.0
    with full_disk, executor(reconstruct_frames, payload, install, workers=n_workers, scheduler=scheduler,
                             isolate=on.isolate) as (submit, label, in_flight):
        pending: set[Future] = set()
        queue = list(todo)
        seconds: list[float] = []  # finished frames' own seconds: how many make a task
        while queue or pending:  # frames finish about in order
            while queue and len(pending) < in_flight:
                # the last tasks split what is left between them, so no worker waits on another's batch
                batch = queue[:min(frames_per_task(seconds, task_seconds), -(-len(queue) // in_flight))]
                del queue[:len(batch)]
                pending.add(submit([(i, frames[i], grids[i]) for i in batch]))
            finished, pending = wait_some(pending, cancel)
            for fut in finished:
                recs = fut.result()
                store.record(out, *recs)  # one fsync a task, not one a frame
                for rec in recs:
                    records[rec["index"]] = rec
                    seconds.append(rec["seconds"] if frame_seconds is None else frame_seconds(rec))
                    if on_frame is not None:
                        on_frame(rec, len(records), total)
    return SequenceReport(bounds, dtype.name, [records[i] for i in range(total)], len(done), len(todo),
                          time.perf_counter() - t0, rest, label, colours)


def describe_palette(indexed) -> str:
    """What a colour sequence's palette keeps of the source's colours, in words."""
    if indexed.exact:
        return f"colour: {indexed.colours} palette colours, exact"
    mean, p95 = indexed.error
    return (f"colour: {indexed.colours} palette colours, quantised (CIEDE2000 mean {mean:.2f}, "
            f"95th percentile {p95:.2f})")


# A Dask task costs ~3 ms of scheduler round trip on the workers' own cores (measured: 100 tasks of a
# 50 ms busy loop on 2 workers), plus its share of the scheduler's and nannies' CPU: a 30 ms mannequin
# frame a task ran 30-45 % slower than on a local pool; tasks of half a second keep the round trip
# under 1 %, and a kill loses at most half a second per worker.
DASK_TASK_SECONDS = 0.5


def frames_per_task(seconds: list[float], task_seconds: float, most: int = 16) -> int:
    """How many frames make one task of about ``task_seconds``, from the frames finished so far
    (their median: a crumble's frames grow slower as its heap grows). One until a frame has been
    timed, and one on a local pool (``task_seconds`` 0), whose tasks cost microseconds -- a task's
    frames are recorded together when it ends, so a killed run redoes at most one task per worker."""
    if task_seconds <= 0 or not seconds:
        return 1
    return int(min(most, max(1, round(task_seconds / max(float(np.median(seconds[-32:])), 1e-3)))))


def _rest_filled(conn) -> int:
    """Filled voxels of the rest pose (every mode covers the same voxels): each frame's loss is against it."""
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.tskel_tools import identity_tskel

    r = reconstruct(identity_tskel(conn), mode="bone")
    return int(r.stats["filled"])
