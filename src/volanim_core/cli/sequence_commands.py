"""``volanim sequence``: many frames into one OME-Zarr time series, resumable, on all cores or a Dask cluster."""

from __future__ import annotations

import sys

from volanim_core.progress import TextProgress

from ._common import (
    FrameProgress,
    add_command,
    add_dims,
    add_joints,
    add_pool,
    ascii_int,
    checked_by,
    dask_scheduler,
    joints_of,
    load_scan,
    load_source,
    local_workers,
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
    save,
)

EXAMPLE = (
    "volanim sequence mannequin.0.50.connect walk/*.trans --source mannequin.VOL --mode sampled -o walk.zarr",
    "volanim sequence mannequin.0.50.connect walk.bvh --bones mannequin.bones --frames 0:240:8 \\\n"
    "--mode bone --melt 12 --workers 2 -o melt.zarr",
    "volanim sequence mannequin.0.50.connect walk/*.trans --mode bone --crumble 12 -o crumble.zarr   # into a heap",
    "volanim sequence mannequin.0.50.connect walk/*.trans --joints smooth --mode bone -o smooth.zarr",
    "volanim sequence mannequin.0.50.connect walk/*.trans --source mannequin.VOL --mode sampled -o walk.zarr"
    "   # again: done frames are skipped",
)


def _sequence(args):
    from volanim_core.io import read_bones, read_connect
    from volanim_core.io.mapping_files import read_mapping
    from volanim_core.parallel import RunOn
    from volanim_core.sequence.effects import crumble, melt, teleport
    from volanim_core.sequence.frames import frames_from_files
    from volanim_core.sequence.run import SequenceSettings, run_sequence

    conn = joints_of(args, read_connect(args.connect))
    bones = read_bones(args.bones) if args.bones else None
    frames = frames_from_files(conn, args.frames, bones=bones, mapping=read_mapping(args.map) if args.map else None,
                               frames=args.range, up=args.up, forward=args.forward, check=not args.no_check,
                               animation=args.animation)
    if not args.crumble and (args.acceleration or args.heap != "keep"):
        raise ValueError("--acceleration and --heap shape a crumble: give --crumble N")
    if args.melt and args.teleport:
        raise ValueError("--melt and --teleport are two ends: give one (--melt combines with --crumble)")
    if args.crumble:  # with --melt the spheres shrink while they fall (the thesis's melt and crumble at once)
        frames += crumble(frames, args.crumble, down=args.down, acceleration=args.acceleration, heap=args.heap,
                          melt=args.melt or 0, conn=conn)
    elif args.melt:
        frames += melt(frames, args.melt)
    elif args.teleport:
        frames += teleport(conn, frames, args.teleport, down=args.down)
    source, source_geometry = load_source(args, conn, colour=True)  # a colour scan: a colour sequence
    workers = local_workers(args)
    settings = SequenceSettings(mode=args.mode, source=source, source_geometry=source_geometry, kernel=args.kernel,
                                padding=args.padding, fps=args.fps, every_frame_as=args.every_frame_as)
    with dask_scheduler(args) as scheduler:
        on = RunOn(workers=workers, scheduler=scheduler, threads_per_worker=args.threads_per_worker)
        rep = run_sequence(conn, frames, args.output, settings, on=on, existing="redo" if args.force else "resume",
                           on_frame=FrameProgress())
    print(file=sys.stderr)
    print(format_report(rep))
    from volanim_core.sequence.store import ome_scale

    if not ome_scale(conn.geometry)[1]:
        print(f"note: the scan's axes are swapped or tilted ({conn.geometry.describe()}): OME-Zarr's scale and "
              "translation cannot say so, and a viewer that reads only them shows the frames beside the scan; "
              "the store's volanim attributes hold the full geometry")
    if rep.colours:
        print(rep.colours)
    print(f"wrote {args.output}: {len(frames)} frames of {'x'.join(map(str, rep.bounds.shape))} ({rep.dtype}), "
          f"origin {rep.bounds.lo}; {rep.computed} made, {rep.skipped} already complete; {rep.workers}; "
          f"{rep.seconds:.1f} s")
    print(cost_line(rep, args.output))


def cost_line(rep, store) -> str:
    """What a frame cost and what the store holds (#87: a user sizing a cluster run reads this line)."""
    from volanim_core.limits import human_bytes
    from volanim_core.sequence.store import bytes_on_disk

    recs, size = rep.records, bytes_on_disk(store)  # every frame of the store: a resumed run's too
    made = f"{rep.seconds / rep.computed:.2f} s a frame made this run; " if rep.computed else ""
    worker = (f"a frame {sum(r['seconds'] for r in recs) / len(recs):.2f} s on its worker (mean), worker peak "
              f"{human_bytes(max(r['peak_rss'] for r in recs))}; ")
    return f"{made}{worker}store {human_bytes(size)}, {human_bytes(size / len(recs))} a frame"


def _crumble(args):
    from volanim_core.io.volume_files import WRITE_SUFFIXES, natural_order
    from volanim_core.sequence.effects import fall_series
    from volanim_core.sequence.task import check_frame_pattern

    check_frame_pattern(args.output, "-o", tuple(s.lower() for s in dict.fromkeys(WRITE_SUFFIXES)))
    paths = natural_order(args.volumes)
    last = args.start + args.n - 1
    if args.frame is not None and not args.start <= args.frame <= last:
        raise ValueError(f"--frame {args.frame} is not one of the crumble's frames {args.start}..{last}")
    scans = _Scans(paths, args)  # read when a frame needs them: --frame K reads the first and its own
    bar = TextProgress("crumble")
    wanted = None if args.frame is None else [args.frame - args.start + 1]  # the thesis's desiredFrame
    frames = fall_series(scans, args.n, args.down, acceleration=args.acceleration, heap=args.heap, frames=wanted)
    for done, (k, vol) in enumerate(frames, start=1):
        save(args.output % (k + args.start - 1), vol, scans.geometry)
        bar(done, args.n if wanted is None else 1)
    bar.close()
    if wanted is None:
        print(f"{args.n} frames from {len(paths)} volume{'s' * (len(paths) > 1)} -> {args.output % args.start} .. "
              f"{args.output % (args.start + args.n - 1)}")
    else:
        print(f"frame {args.frame} of {args.n} from {len(paths)} volume{'s' * (len(paths) > 1)} -> "
              f"{args.output % args.frame}")


class _Scans:
    """The crumble's volumes as a sequence read on first use (and kept: a held volume serves many frames)."""

    def __init__(self, paths, args):
        self.paths, self.args, self.read = paths, args, {}

    def __len__(self) -> int:
        return len(self.paths)

    def scan(self, i: int):
        if i not in self.read:
            self.read[i] = load_scan(self.paths[i], self.args)
        return self.read[i]

    def __getitem__(self, i: int):
        return self.scan(i).data

    @property
    def geometry(self):
        return self.scan(0).geometry


def format_report(rep) -> str:
    """The per-frame table: filled voxels, loss against the rest pose, hotspot max, clipped, time, memory."""
    lines = ["frame   filled voxels   loss %   hotspot max   clipped   seconds   worker peak MB"]
    for r in rep.records:
        loss = 100.0 * (rep.rest_filled - r["filled"]) / max(rep.rest_filled, 1)
        hot = "-" if r.get("hotspot_max") is None else str(r["hotspot_max"])
        lines.append(f"{r['number']:5d}   {r['filled']:13,d}   {loss:6.2f}   {hot:>11}   {r['clipped']:7d}   "
                     f"{r['seconds']:7.3f}   {r['peak_rss'] / 2**20:14.0f}")
    return "\n".join(lines)


def _fall_options(p, what: str, down: str | None = None) -> None:
    """--acceleration, --heap and --down, as ``volanim crumble`` and ``sequence --crumble`` share them
    (choices: ``sequence.effects.HEAPS``, not imported here to keep ``volanim --help`` light)."""
    p.add_argument("--acceleration", type=non_negative_float, default=0.0, metavar="A",
                   help=f"{what}fall a*k^2/2 voxels by frame k (default: the top lands on the last frame)")
    p.add_argument("--heap", choices=("keep", "sum"), default="keep",
                   help=f"{what}a heap voxel keeps its value (default), or holds the sum of what rests on it, "
                        "capped (the thesis's multiVolumeMelt)")
    p.add_argument("--down", default="-z", type=checked_by("volanim_core.sequence.effects:parse_axis"),
                   help=f"{what if down is None else down}the way down (default -z)")


def register(sub) -> None:
    from volanim_core.reconstruct.engine import MODES

    p = add_command(sub, "crumble", "Any volume, or a numbered series of them, falls into a heap frame by frame "
                    "(the thesis's multiVolumeMelt): one output volume a frame.",
                    ("volanim crumble mannequin.VOL -n 4 --heap sum -o mannequin-heap.%04d.VOL",
                     "volanim crumble mannequin-heap.0001.VOL mannequin-heap.0002.VOL -n 2 --acceleration 20 "
                     "-o again.%04d.nrrd   # a series: one volume a frame"),
                    _crumble)
    p.add_argument("volumes", nargs="+",
                   help="one volume (held), one for each frame, or fewer than frames, each held for an equal run "
                        "of them, as the thesis fed multiVolumeMelt a few frames (numbered: taken in order)")
    p.add_argument("-n", type=positive_int, required=True, help="frames; the top lands on the last one")
    p.add_argument("-o", "--output", required=True, metavar="DIR/NAME.%%04d.VOL",
                   help="the frames' files (any volume format; %%04d = frame number)")
    p.add_argument("--start", type=non_negative_int, default=1, help="number of the first frame (default 1)")
    p.add_argument("--frame", type=non_negative_int, metavar="K",
                   help="write frame K alone, as the thesis's desiredFrame (numbered as --start numbers them)")
    _fall_options(p, "")
    add_dims(p)

    from .motion_commands import parse_frames

    p = add_command(sub, "sequence", "Reconstruct many frames into one OME-Zarr time series (t, z, y, x): one grid "
                    "for all frames, resumable, on all local cores or a Dask cluster.", EXAMPLE, _sequence)
    p.add_argument("connect", help="the .connect every frame uses")
    p.add_argument("frames", nargs="+", help=".trans or .tskel files (numbered NAME.0000.trans ...), or one clip "
                                             "(.bvh, glTF .glb/.gltf/.vrma, .fbx)")
    p.add_argument("--source", help="rest-pose volume, grey or colour (needed for --mode sampled; a colour one "
                                    "makes a colour sequence: palette indices, the palette in the store)")
    add_dims(p)  # --dims for a headerless .vol source, --series for a DICOM folder of several
    p.add_argument("--mode", choices=MODES, default="binary", help="default binary")
    p.add_argument("--kernel", type=ascii_int, choices=(1, 3, 5), default=1, help="sampled: Gaussian kernel size")
    p.add_argument("--padding", type=ascii_int, default=2, help="voxels around every frame's spheres (default 2)")
    add_joints(p, "the .connect's (rigid when it records none)")
    p.add_argument("-o", "--output", required=True, help="the .zarr store (a folder)")
    p.add_argument("--every-frame-as", metavar="DIR/NAME.%%04d.vti",
                   type=checked_by("volanim_core.sequence.task:check_frame_pattern", "--every-frame-as {text!r} "),
                   help="also write each frame as a file (.vti, .nrrd, .vol, .VOL; %%04d = frame number)")
    add_pool(p, "run")
    p.add_argument("--threads-per-worker", type=positive_int, default=1, help="numba threads per worker (default 1)")
    p.add_argument("--force", action="store_true", help="recompute every frame (and replace another sequence)")
    p.add_argument("--fps", type=positive_float, default=24.0, help="frame rate recorded in the store (default 24)")
    effect = p.add_mutually_exclusive_group()
    p.add_argument("--melt", type=positive_int, metavar="N",
                   help="after the frames, N more: every DT shrinks to 0 (with --crumble: while it falls)")
    effect.add_argument("--teleport", type=positive_int, metavar="N",
                        help="after the frames, N more: the body vanishes from the head down")
    effect.add_argument("--crumble", type=positive_int, metavar="N",
                        help="after the frames, N more: the voxels fall and pile into a heap")
    _fall_options(p, "crumble: ", down="teleport/crumble: ")
    p.add_argument("--bones", help="a BVH frame source needs the .bones it drives")
    p.add_argument("--map", help="BVH: BONE BVH_JOINT per line (default: suggested)")
    p.add_argument("--animation",
                   help="glTF, FBX: which of the clip's animations, by name or number (default the first)")
    p.add_argument("--frames", dest="range", type=parse_frames, default=slice(None), metavar="START:STOP:STEP",
                   help="BVH: which frames")
    p.add_argument("--up", default="auto", help="BVH: the clip's up axis (default detected)")
    p.add_argument("--forward", default="auto", help="BVH: the way the clip faces (default detected)")
    p.add_argument("--no-check", action="store_true",
                   help="BVH: run a clip that fails bvh2trans's checks (another kind of figure, lying down) anyway")
