"""Render many frames to pictures and a movie: one camera, all local cores or a Dask cluster, resumable.

    inputs (a zarr sequence, or volume files) --open_inputs--> FrameRefs + the box every frame fits
    FrameRefs not yet drawn --executor.submit(render_task)--> (number, RGB image) --> NAME.0000.png (atomic)
    every PNG --encode--> .mp4 (imageio-ffmpeg's own ffmpeg) or .gif

Each worker keeps one off-screen plotter for all its frames. Pictures are
written by the driver only, each atomically, so a run killed at any moment
leaves whole PNGs; rerunning with the same settings draws only the missing
ones (``volanim-render.json`` holds the settings' key; other settings start over).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from volanim_core.io.files import resolved
from volanim_core.parallel import THIS_PROCESS, RunOn, executor, wait_some

from .scene import Renderer, RenderSettings
from .views import Camera, union_box

KEY_FILE = "volanim-render.json"
MOVIES = (".mp4", ".gif")


@dataclass(frozen=True)
class FrameRef:
    path: str
    index: int  # the frame inside a zarr sequence (-1: a volume file)
    number: int  # the frame's number (file names, the overlay)
    camera: Camera | None = None  # this frame's own camera (``--camera follow``), else the settings'


@dataclass
class RenderInputs:
    frames: list[FrameRef]
    lo: tuple  # the voxel box every frame's body fits in (the camera frames it): the union of ``boxes``
    hi: tuple
    mode: str | None  # the reconstruction mode, when the input says
    vmax: float  # the top of the colour range over every frame
    fps: float | None
    fingerprint: list  # what the pictures depend on besides the settings (for resuming)
    boxes: list | None = None  # per frame: its filled voxels' (lo, hi), None when empty; None: not known
    spacing: tuple = (1.0, 1.0, 1.0)  # world units per voxel (files: their own; sequences: voxels)
    unverified: int = 0  # sequence frames read without a checksum to compare (stores older than regions)

    def world_box(self, box=None) -> tuple[np.ndarray, np.ndarray]:
        """``box`` (voxel centres ``(lo, hi)``; default: the one every frame's body fits in) in world units
        (voxel x spacing), to the voxels' faces."""
        lo, hi = (self.lo, self.hi) if box is None else box
        sp = np.asarray(self.spacing, np.float64)
        return (np.asarray(lo) - 0.5) * sp, (np.asarray(hi) + 0.5) * sp

    def follow(self, view: str, aspect: float, axes=None, base: Camera | None = None) -> list[FrameRef]:
        """The frames, each with a camera that keeps its body in the middle (:func:`follow_cameras`; ``base``:
        a camera whose direction and distance every frame keeps, e.g. the studio's view)."""
        from .views import follow_cameras

        boxes = self.boxes or [(self.lo, self.hi)] * len(self.frames)
        world = [None if b is None else self.world_box(b) for b in boxes]
        cams = follow_cameras(view, world, aspect=aspect, axes=axes, base=base)
        return [replace(f, camera=c) for f, c in zip(self.frames, cams)]


def open_inputs(paths, frames: slice = slice(None), dims=None) -> RenderInputs:
    """Frames to render from one zarr sequence or from volume files (in frame-number order)."""
    paths = [sequence_folder(Path(p)) for p in paths]
    if not paths:
        raise ValueError("nothing to render: give a volume file, several, or a .zarr sequence")
    zarrs = [p for p in paths if (p / "volanim-plan.json").is_file() or p.suffix.lower() == ".zarr"]
    if zarrs:
        if len(paths) != 1:
            raise ValueError("render one .zarr sequence, or volume files, not both")
        return _zarr_inputs(paths[0], frames)
    return _file_inputs(paths, frames, dims)


def sequence_folder(path: Path) -> Path:
    """A file picked inside a zarr sequence (its ``zarr.json`` or ``volanim-plan.json``: a file dialog
    cannot pick a folder) stands for the sequence; any other path is itself."""
    path = Path(path)
    if path.name in ("zarr.json", "volanim-plan.json", ".zgroup", ".zattrs") and \
            (path.parent / "volanim-plan.json").is_file():
        return path.parent
    return path


def _zarr_inputs(path: Path, frames: slice) -> RenderInputs:
    from volanim_core.sequence.checked import read_store

    seq = read_store(path)  # every key checked once, sizes before allocation (FormatError names the file)
    done, numbers = seq.done, seq.numbers
    indices = list(range(seq.frames))[frames]
    if not indices:
        raise ValueError(f"{path}: the frame range selects none of its {seq.frames} frames")
    missing = [i for i in indices if i not in done]
    if missing:
        raise ValueError(f"{path}: {len(missing)} of the frames to render are not reconstructed yet (first: frame "
                         f"{numbers[missing[0]]}); finish them with `volanim sequence` (rerun it: it resumes)")
    lo = seq.origin_xyz
    hi = tuple(o + n - 1 for o, n in zip(lo, seq.shape_zyx[::-1]))
    mode, dtype = seq.mode, seq.dtype
    if mode == "hotspot":
        vmax = max(float(done[i].get("hotspot_max") or 1) for i in indices)
    else:
        vmax = float(np.iinfo(dtype).max) if dtype.kind in "ui" else 1.0
        if dtype.itemsize > 1 or dtype.kind == "f":
            vmax = float(np.max(seq.read_part(indices[len(indices) // 2])[0]))  # a middle frame's brightest voxel
    scale = seq.seconds_per_frame
    refs = [FrameRef(str(resolved(path)), i, int(numbers[i])) for i in indices]
    boxes = None
    if all("box" in done[i] for i in indices):  # stores written before boxes were recorded: the grid
        boxes = [None if done[i]["box"] is None else (tuple(done[i]["box"][0]), tuple(done[i]["box"][1]))
                 for i in indices]
    body_lo, body_hi = union_box(boxes or [], lo, hi)
    return RenderInputs(refs, body_lo, body_hi, mode, vmax, 1.0 / float(scale),
                        [seq.key, *[done[i]["sha256"] for i in indices]], boxes,
                        unverified=sum(not seq.verified(i) for i in indices))


def _file_inputs(paths: list[Path], frames: slice, dims) -> RenderInputs:
    from volanim_core.io.frame_files import frame_number

    numbers = [frame_number(p) for p in paths]
    if None in numbers or len(set(numbers)) != len(numbers):
        numbers = list(range(len(paths)))  # their order on the command line
    pairs = sorted(zip(numbers, paths))[frames]
    if not pairs:
        raise ValueError("the frame range selects none of the files")
    from volanim_core.volume import tight_bounds

    los, his, boxes, vmax, fingerprint, spacing, modes = [], [], [], 1.0, [], None, set()
    for _, p in pairs:  # every file once: the box and the colour range must hold for all of them
        vol, origin, sp, mode = _read(p, dims)
        modes.add(mode)
        if spacing is None:
            spacing = tuple(float(v) for v in sp)
        elif not np.allclose(sp, spacing, rtol=1e-4):
            raise ValueError(f"{p}: voxels of {_mm(sp)}, the first file's are {_mm(spacing)}; render files of one "
                             f"voxel size together (volanim resample makes them so)")
        o = np.rint(np.asarray(origin, np.float64)).astype(int)
        los.append(o)
        his.append(o + np.array(vol.shape[:3]) - 1)
        box = tight_bounds(vol.any(axis=3) if vol.ndim == 4 else vol)
        boxes.append(None if box is None else (tuple((o + box.lo).tolist()), tuple((o + box.hi).tolist())))
        if vol.size:
            vmax = max(vmax, float(vol.max()))
        st = p.stat()
        fingerprint.append([str(resolved(p)), st.st_size, st.st_mtime_ns])
    refs = [FrameRef(str(resolved(p)), -1, int(n)) for n, p in pairs]
    lo, hi = union_box(boxes, np.min(los, 0).tolist(), np.max(his, 0).tolist())
    mode = modes.pop() if len(modes) == 1 else None  # the files' recorded mode, when they agree
    return RenderInputs(refs, lo, hi, mode, vmax, None, fingerprint, boxes, spacing)


def _mm(spacing) -> str:
    return " x ".join(f"{v:g}" for v in spacing) + " mm"


def _read(path, dims=None):
    from volanim_core.io import read_scan

    scan = read_scan(path, dims=dims, colour=True)  # a colour volume is drawn in its colours
    g = scan.geometry  # frames are drawn in voxels: the origin in voxels of the frame's own spacing
    return scan.data, tuple(np.asarray(g.origin) / np.asarray(g.spacing)), g.spacing, scan.mode


@dataclass
class RenderJob:
    settings: RenderSettings
    dims: tuple | None = None


_JOB: RenderJob | None = None
_RENDERER: Renderer | None = None


def install(job: RenderJob) -> None:
    """A worker's initializer: keep the job; its plotter is made at the first frame."""
    global _JOB
    release()
    _JOB = job


def release() -> None:
    """Close this process's plotter (a pool worker's goes with the process; this one must not outlive
    the display it was opened on)."""
    global _RENDERER
    if _RENDERER is not None:
        _RENDERER.close()
        _RENDERER = None


def render_task(job: RenderJob | None, ref: FrameRef) -> tuple[int, np.ndarray]:
    """Draw one frame; returns its number and the picture (the driver writes it)."""
    global _RENDERER, _JOB
    job = job if job is not None else _JOB
    if job is None:
        raise RuntimeError("render_task: no job (the pool's initializer did not run)")
    if _RENDERER is None or _RENDERER.settings != job.settings:
        if _RENDERER is not None:
            _RENDERER.close()
        _RENDERER, _JOB = Renderer(job.settings), job  # one plotter per worker, reused for every frame
    volume, origin = read_frame(ref, job.dims, colour=job.settings.transfer is None)
    return ref.number, _RENDERER.render(volume, origin, ref.number, camera=ref.camera)


def read_frame(ref: FrameRef, dims=None, colour: bool = True) -> tuple[np.ndarray, tuple]:
    """One input frame as ``(volume [x, y, z], origin in voxels)``. A colour sequence's frame is its
    colours ``[x, y, z, 3]`` (its indices through its palette), or with ``colour=False`` its indices
    (what a user's transfer function over the palette reads: ``render --tf``). A sequence's frame is its
    recorded region placed at its corner, never the shared grid (a full-size walk's holds 31.5 G voxels)."""
    if ref.index >= 0:
        from volanim_core.sequence.checked import read_store

        seq = read_store(ref.path)
        part, corner = seq.read_colour_part(ref.index) if colour and seq.palette is not None else \
            seq.read_part(ref.index)
        return part, tuple(o + c for o, c in zip(seq.origin_xyz, corner))
    volume, origin, *_ = _read(ref.path, dims)
    return volume, origin


def choose_mapper(inputs: RenderInputs, settings: RenderSettings, dims=None) -> RenderSettings:
    """Resolve ``mapper="auto"`` for a volume-style sequence: time one warm frame with each mapper here and
    keep the faster for every worker (one look for the whole movie). Neither wins everywhere on software
    OpenGL -- bench_render: the CPU caster is 4-7x faster on the walking mannequin, VTK's smart mapper 4x
    on the frog -- and the test costs four pictures."""
    from dataclasses import replace

    if settings.style != "volume" or settings.mapper != "auto":
        return settings
    if len(inputs.frames) < 4:
        return replace(settings, mapper="gpu")
    ref = inputs.frames[len(inputs.frames) // 2]
    seconds = {}
    for mapper in ("gpu", "cpu"):
        install(RenderJob(replace(settings, mapper=mapper), dims))
        try:
            render_task(None, ref)  # builds the plotter and the volume actor
            t0 = time.perf_counter()
            render_task(None, ref)
            seconds[mapper] = time.perf_counter() - t0
        finally:
            release()
    return replace(settings, mapper=min(seconds, key=seconds.get))


def output_kind(out: Path) -> str:
    """``png`` (one picture), ``mp4``/``gif`` (a movie) or ``folder`` (numbered PNGs)."""
    suffix = out.suffix.lower()
    if suffix == ".png":
        return "png"
    if suffix in MOVIES:
        return suffix[1:]
    if suffix and not out.is_dir():
        raise ValueError(f"{out}: render to a .png, .mp4, .gif or a folder (no extension)")
    return "folder"


def check_output(text: str) -> None:
    """Refuse (ValueError) a name that is no picture, movie or folder."""
    output_kind(Path(text))


def check_size(size, kind: str) -> None:
    w, h = size
    if kind == "mp4" and (w % 16 or h % 16):
        raise ValueError(f"a video is encoded in 16x16 blocks: --size {w}x{h} must be multiples of 16 "
                         f"(e.g. {max(16, w // 16 * 16)}x{max(16, h // 16 * 16)})")


@dataclass
class RenderReport:
    out: Path
    frames: int
    drawn: int
    skipped: int
    seconds: float
    workers: str
    fps: float
    mapper: str = ""


def render(inputs: RenderInputs, settings: RenderSettings, out, *, fps: float | None = None, on: RunOn = THIS_PROCESS,
           force: bool = False, keep_frames: bool = False, dims=None, on_frame=None, cancel=None) -> RenderReport:
    """Render every frame of ``inputs`` to ``out``; see the module docstring.

    ``on``: where the pictures are drawn; ``on.isolate``: in worker processes only, never in this one.
    ``on_frame(number, done, total)`` after each picture (progress; it may raise to stop the run).
    ``cancel()``: asked while pictures are being drawn, not only when one arrives (Cancelled).
    """
    t0 = time.perf_counter()
    out = Path(out)
    kind = output_kind(out)
    settings.check()
    check_size(settings.size, kind)
    fps = float(fps or inputs.fps or 24.0)
    if not 0 < fps <= 1000:
        raise ValueError(f"fps must be above 0 and at most 1000, got {fps:g}")
    total = len(inputs.frames)
    if not on.isolate:  # timing both mappers draws here
        settings = choose_mapper(inputs, settings, dims)
    if kind == "png" and total != 1:
        raise ValueError(f"{total} frames do not fit in one .png: render to a folder, an .mp4 or a .gif")
    job = RenderJob(settings, dims)
    if kind == "png":
        try:
            with executor(render_task, job, install, workers=1, isolate=on.isolate) as (submit, label, _):
                number, image = submit(inputs.frames[0]).result()
        finally:
            release()
        write_png(out, image)
        if on_frame is not None:
            on_frame(number, 1, 1)
        return RenderReport(out, 1, 1, 0, time.perf_counter() - t0, label, fps, settings.mapper)
    folder = out if kind == "folder" else out.parent / f".{out.name}.frames"
    key = _key(inputs, settings)
    todo, skipped = _plan_folder(folder, key, inputs.frames, force)
    done = total - len(todo)
    label = "nothing to draw"
    try:
        if todo:
            try:
                label = _draw(todo, job, folder, on, on_frame, done, total, cancel)
            finally:
                release()
        if kind in ("mp4", "gif"):
            encode([frame_path(folder, f.number) for f in inputs.frames], out, fps)
    except OSError:  # a full disk: a movie's hidden frames are no use to the user (a kill keeps them to resume)
        if kind in ("mp4", "gif") and not keep_frames:
            shutil.rmtree(folder, ignore_errors=True)
        raise
    if kind in ("mp4", "gif") and not keep_frames:
        shutil.rmtree(folder, ignore_errors=True)
    return RenderReport(out, total, len(todo), skipped, time.perf_counter() - t0, label, fps, settings.mapper)


def _draw(todo, job, folder, on: RunOn, on_frame, done, total, cancel=None) -> str:
    """Draw ``todo`` anywhere; the driver writes each picture as it arrives. Returns where it ran."""
    with executor(render_task, job, install, workers=min(on.workers or 1, len(todo)), scheduler=on.scheduler,
                  isolate=on.isolate) as (submit, label, in_flight):
        pending, queue = set(), list(todo)
        while queue or pending:  # pictures arrive about in order
            while queue and len(pending) < in_flight:
                pending.add(submit(queue.pop(0)))
            finished, pending = wait_some(pending, cancel)
            for fut in finished:
                number, image = fut.result()
                write_png(frame_path(folder, number), image)
                done += 1
                if on_frame is not None:
                    on_frame(number, done, total)
    return label


def frame_path(folder: Path, number: int) -> Path:
    return Path(folder) / f"frame.{number:04d}.png"


def write_png(path, image: np.ndarray) -> None:
    import imageio.v3 as iio

    from volanim_core.io.atomic import atomic_write_bytes

    atomic_write_bytes(path, iio.imwrite("<bytes>", image, extension=".png"))


def _key(inputs: RenderInputs, settings: RenderSettings) -> str:
    def plain(v):
        if isinstance(v, np.ndarray):
            return v.tolist()
        return str(v)

    text = json.dumps([asdict(settings), inputs.fingerprint, [asdict(f) for f in inputs.frames]], default=plain,
                      sort_keys=True)
    return hashlib.blake2b(text.encode(), digest_size=16).hexdigest()


def _plan_folder(folder: Path, key: str, frames: list[FrameRef], force: bool) -> tuple[list[FrameRef], int]:
    """The frames still to draw into ``folder``: all of them unless the folder holds this render's pictures."""
    from volanim_core.io.atomic import atomic_write_text

    if folder.exists() and not folder.is_dir():
        raise ValueError(f"{folder} is a file; render to a folder, a .png, an .mp4 or a .gif")
    folder.mkdir(parents=True, exist_ok=True)
    old = None
    try:
        old = json.loads((folder / KEY_FILE).read_text()).get("key")
    except (OSError, ValueError, AttributeError):
        pass
    if force or old != key:
        atomic_write_text(folder / KEY_FILE, json.dumps({"key": key, "frames": len(frames)}))
        return list(frames), 0  # other settings: every picture is redrawn (and replaced)
    todo = [f for f in frames if not frame_path(folder, f.number).is_file()]
    return todo, len(frames) - len(todo)


def encode(pngs: list[Path], out: Path, fps: float) -> None:
    """The pictures as one movie: H.264 ``.mp4`` (yuv420p, plays everywhere) or a looping ``.gif``."""
    import imageio.v2 as iio2
    import imageio.v3 as iio

    from volanim_core.io.atomic import clean_stale, naming_the_output, pending_name

    out.parent.mkdir(parents=True, exist_ok=True)
    clean_stale(out.parent, out.name)
    tmp = out.parent / (pending_name(out.name) + out.suffix)  # the encoder picks the format by extension
    pictures = sum(p.stat().st_size for p in pngs)
    with naming_the_output(out, "the movie", f"about {pictures:,} bytes (its pictures' size)"):
        try:
            if out.suffix.lower() == ".mp4":
                with iio2.get_writer(tmp, format="FFMPEG", fps=fps, codec="libx264", quality=8, macro_block_size=16,
                                     pixelformat="yuv420p", ffmpeg_log_level="error") as writer:
                    for p in pngs:
                        writer.append_data(iio.imread(p))
            else:
                frames = [iio.imread(p) for p in pngs]
                # GIF delays are whole centiseconds: spread the rounding so the clip keeps its length
                # (24 fps as 4 cs each would play 4 % slow). Identical neighbours are merged by Pillow, their
                # delays added: the frame count may drop, the timing does not.
                ticks = np.round(np.arange(len(frames) + 1) * 100.0 / fps)
                iio.imwrite(tmp, frames, extension=".gif", duration=list(np.diff(ticks) * 10.0), loop=0)
            os.replace(tmp, out)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
