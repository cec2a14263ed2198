"""Long jobs of the studio, Qt-free (the Logic of Slicer's Widget/Logic split).

Each takes ``progress`` and ``cancel`` and returns a plain dict that the main
window hands to the Document on the GUI thread. The CLI's functions do the
work; nothing here knows a window exists.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from volanim_core import samples
from volanim_core.geometry import IDENTITY
from volanim_core.io import read_scan, read_skeleton
from volanim_core.progress import Reporter, stage
from volanim_core.skeleton.hull import display_hulls, vertex_normals
from volanim_core.skeleton.skeletonize import DEFAULT_MIN_THINNESS, skeletonize
from volanim_core.volume import is_colour, isotropic_mask, resample, segment, to_grey


@dataclass(frozen=True)
class Segmentation:
    """How a scan is segmented and skeletonized: ``volanim skeletonize``'s ``--threshold LO[:HI]``,
    ``--fill-cavities``, ``--metric`` and ``--min-thinness`` (a project saves them as a dict)."""

    lo: float
    hi: float | None = None
    fill: bool = False
    metric: str = "euclid"
    min_thinness: float = DEFAULT_MIN_THINNESS

    @classmethod
    def of(cls, params: dict) -> Segmentation:
        """The segmentation a dialog's or a project's parameters hold (other keys ignored)."""
        return cls(**{f.name: params[f.name] for f in fields(cls) if f.name in params})

    def as_dict(self) -> dict:
        return asdict(self)


def prepare_volume(volume: np.ndarray, segmentation: Segmentation, *, skeleton_path=None, grey=None, geometry=None,
                   progress=None, cancel=None) -> dict:
    """Segment, skeletonize and isosurface a loaded volume.

    ``skeleton_path``: a saved ``.mskel`` of this segmentation (a reopened
    project) is read instead of skeletonizing again. ``grey``: a colour volume's
    luminance when the caller has it (:func:`load_volume_file` made it already).
    ``geometry``: where the scan's voxels are. When they are not cubes, the mask is
    resampled to cubes as ``volanim skeletonize`` does (:func:`volume.isotropic_mask`)
    and the volume with it (nearest voxel: the values sampled mode reads), so the
    studio works on the same grid as the command line; the result's ``geometry`` is it.
    """
    report = Reporter(progress, cancel)
    report(0, 100)
    if grey is None:  # a colour scan is segmented on its luminance
        grey = to_grey(volume) if is_colour(volume) else volume
    lo, hi = segmentation.lo, segmentation.hi
    mask = segment(grey, lo, hi, fill=segmentation.fill)  # the command line's own segmentation
    if not mask.any():
        raise ValueError(f"no voxel lies in the threshold range {lo}..{hi if hi is not None else 'max'}")
    report(5, 100)
    if geometry is not None and not geometry.is_isotropic:
        mask, cubes = isotropic_mask(mask, geometry, progress=stage(report, 5, 8), cancel=cancel)
        volume = on_grid(volume, geometry, cubes)
        geometry = cubes
    report(10, 100)

    if skeleton_path:
        skel = read_skeleton(skeleton_path).one_level()
    else:
        skel = skeletonize(mask, metric=segmentation.metric, min_thinness=segmentation.min_thinness,
                           geometry=geometry or IDENTITY,
                           progress=stage(report, 10, 80), cancel=cancel)
    report(80, 100)
    hull, lod = display_hulls(mask)  # lod: drawn while a slider is held
    # with their normals: VTK's smooth shading made them on the GUI thread (70 ms of mannequin-large's open)
    hull, lod = ((*h, vertex_normals(*h)) if h is not None else None for h in (hull, lod))
    report(90, 100)
    pieces = regrown_pieces(skel, mask)
    report(100, 100)
    return {"volume": volume, "mask": mask, "skeleton": skel, "hull": hull, "hull_lod": lod,
            "skeleton_path": skeleton_path, "geometry": geometry, "pieces": pieces,
            "segmentation": segmentation.as_dict()}


def regrown_pieces(skeleton, mask: np.ndarray) -> tuple[int, int]:
    """``(pieces the skeleton's balls re-grow, pieces of the segmented body)``, 26-connected. More of the
    first: the minimum thinness kept no points in thin parts, and the rest pose is in pieces before any pose
    (#83: the ant at 0.50 had legs of dashes, and the verdict called it healthy)."""
    from volanim_core.reconstruct.shape import piece_count
    from volanim_core.rig.curve_skeleton import balls

    # counted without holding the GIL (the window draws meanwhile): 1.2 s of a frozen window on mannequin-large
    return piece_count(balls(skeleton)), piece_count(mask)


def on_grid(volume: np.ndarray, geometry, target) -> np.ndarray:
    """``volume`` (grey or colour) resampled onto ``target``'s voxel size, nearest voxel: its own values."""
    if is_colour(volume):
        return np.stack([resample(volume[..., c], geometry, target.spacing, order=0)[0] for c in range(3)], axis=3)
    return resample(volume, geometry, target.spacing, order=0)[0]


def series_choices(path) -> list[tuple[str, str]]:
    """``[(uid, description)]`` of a DICOM folder's series (reads every file's header); [] for anything else."""
    from volanim_core.io.dicom_files import is_dicom_folder, list_series

    if not Path(path).is_dir() or not is_dicom_folder(Path(path)):
        return []
    return list_series(path)


def load_volume_file(path: str, dims=None, series: str | None = None) -> dict:
    """Read any supported volume (fast; the heavy part is :func:`prepare_volume`). A colour volume
    stays in colour (``volume``); ``grey`` is what its threshold is chosen on."""
    from volanim_core.io.mesh_files import READ_MESH_SUFFIXES, read_mesh, voxelize

    if Path(path).suffix.lower() in READ_MESH_SUFFIXES:  # a closed surface: filled, as `volanim voxelize` fills it
        data, geometry = voxelize(read_mesh(path))
        return {"volume": data, "grey": data, "spacing": geometry.spacing, "path": path, "geometry": geometry,
                "segments": {}, "histogram": value_histogram(data)}
    scan = read_scan(path, dims=dims, colour=True, series=series)
    data = scan.data
    grey = to_grey(data) if is_colour(data) else data
    return {"volume": data, "grey": grey, "spacing": scan.geometry.spacing, "path": path, "geometry": scan.geometry,
            "segments": scan.segments, "histogram": value_histogram(grey)}


def value_histogram(volume: np.ndarray) -> tuple[float, float, np.ndarray, np.ndarray]:
    """``(min, max, counts, edges)``: the finite value range of a grey volume and a 256-bin histogram of
    (up to 2 M of) its values, for the threshold dialog (NaN, as in a resampled MRI, is background)."""
    from volanim_core.volume import finite_range

    vmin, vmax = finite_range(volume) or (0.0, 0.0)
    sample = volume.ravel()[:: max(1, volume.size // 2_000_000)]
    sample = sample[np.isfinite(sample)] if sample.dtype.kind == "f" else sample
    counts, edges = np.histogram(sample, bins=256, range=(vmin, vmax if vmax > vmin else vmin + 1))
    return vmin, vmax, counts, edges


def load_demo(name: str, *, skeleton_path=None, progress=None, cancel=None) -> dict:
    """A demo dataset, segmented, skeletonized (or its saved ``.mskel`` read) and with its hull."""
    s = samples.load(name)
    out = prepare_volume(s.volume, Segmentation(lo=s.mask_level), skeleton_path=skeleton_path, progress=progress,
                         cancel=cancel)
    out.update(spacing=s.spacing, sample=s)
    return out


@dataclass(frozen=True)
class MovieSettings:
    """How the studio's movie is made: the preview's mode (and the scan ``source`` it samples, with its
    ``kernel``), the view's ``camera`` in a world of ``spacing`` units, the picture's ``style``, ``size``,
    ``background`` and ``frame_numbers``, the ``fps``, ``follow`` (the camera moved with the body) and the
    user's ``transfer`` function; ``workers``: processes (default: the machine's)."""

    mode: str
    camera: object  # a volanim_core.camera.Camera
    source: np.ndarray | None = None
    kernel: int = 1
    spacing: tuple = (1.0, 1.0, 1.0)
    style: str = "surface"
    size: tuple = (640, 480)
    fps: float = 24.0
    frame_numbers: bool = False
    background: str = "#1e1f24"
    follow: bool = False
    transfer: object = None  # a volanim_core.transfer_function.TransferFunction
    workers: int | None = None


def render_movie(conn, matrices, numbers, out, settings: MovieSettings, *, progress=None, cancel=None) -> dict:
    """The timeline's frames reconstructed (a sequence in one grid) and rendered to ``out`` with the
    studio's camera: the command line's ``volanim sequence`` + ``volanim render``, in worker processes.

    ``settings.follow``: each frame's camera is ``camera`` moved with the body (``RenderInputs.follow``: its
    direction and distance kept, centred on the frame's smoothed filled box), as the timeline follows it.

    A colour ``source`` gives a colour movie: the sequence holds its palette indices and the render draws
    them in the palette's colours (:mod:`volanim_core.colour.indexed`).

    ``settings.transfer``: the user's transfer function (the studio's editor) instead of the mode's colours; over a
    colour movie it reads each voxel's luminance, as the preview does (``through_palette``).

    The sequence is kept beside the movie (``.NAME.zarr``) until the movie is written, and the render's
    pictures likewise, so a cancelled run picks up where it stopped when started again with the same pose.
    """
    import shutil
    import time
    from dataclasses import replace
    from pathlib import Path

    from volanim_core.colour.indexed import through_palette
    from volanim_core.parallel import RunOn, default_workers
    from volanim_core.render.movie import open_inputs, output_kind, render
    from volanim_core.render.scene import RenderSettings
    from volanim_core.sequence.checked import read_store
    from volanim_core.sequence.frames import FrameSpec
    from volanim_core.sequence.run import SequenceSettings, run_sequence

    t0 = time.perf_counter()
    mode, source, camera, spacing = settings.mode, settings.source, settings.camera, settings.spacing
    size, fps, transfer = settings.size, settings.fps, settings.transfer
    report = Reporter(progress, cancel)
    out = Path(out)
    kind = output_kind(out)  # a bad name is refused before anything runs
    frames = [FrameSpec(int(n), np.asarray(m, np.float64)) for n, m in zip(numbers, matrices)]
    if not frames:
        raise ValueError("no frames to render")
    if kind == "png" and len(frames) != 1:
        raise ValueError(f"{len(frames)} frames do not fit in one .png: choose an .mp4, a .gif or a folder")
    colour = mode == "sampled" and source is not None and np.ndim(source) == 4
    first = 3 if colour else 0  # a colour source is indexed first (~1 s, three steps): said on the bar (#83)
    total = first + 2 * len(frames)
    report(0, total)
    cache = out.parent / f".{out.name}.zarr"  # the same frames resume; another pose replaces it
    workers = settings.workers or default_workers()
    how = SequenceSettings(mode=mode, source=source if mode == "sampled" else None, kernel=settings.kernel, fps=fps)
    seq = run_sequence(conn, frames, cache, how, on=RunOn(workers=workers), existing="replace-other",
                       on_frame=lambda rec, done, n: report(first + done, total), cancel=cancel,
                       on_palette=stage(report, 0, first, total))
    inputs = replace(open_inputs([cache]), spacing=tuple(float(s) for s in spacing))  # the studio's world
    if settings.follow:
        inputs = replace(inputs, frames=inputs.follow("front", size[0] / size[1], base=camera))
    palette = read_store(cache).palette if transfer is not None else None
    if palette is not None:
        transfer = through_palette(transfer, palette)  # the frames hold indices: the function of their colours
    look = RenderSettings(camera, style=settings.style, preset=mode, vmax=inputs.vmax, size=tuple(size),
                          background=settings.background, frame_numbers=settings.frame_numbers, transfer=transfer,
                          spacing=tuple(float(s) for s in spacing))
    rep = render(inputs, look, out, on=RunOn(workers=workers, isolate=True), fps=fps,
                 on_frame=lambda number, done, n: report(first + len(frames) + done, total), cancel=cancel)
    shutil.rmtree(cache, ignore_errors=True)
    return {"out": out, "frames": len(frames), "seconds": time.perf_counter() - t0, "workers": rep.workers,
            "colours": seq.colours}
