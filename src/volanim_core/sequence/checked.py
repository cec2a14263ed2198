"""A sequence store's metadata, checked once, before anything is indexed or allocated; frames read verified.

    OUT.zarr/volanim-plan.json     --> plan: key, frames (1..MAX_FRAMES), numbers (one per frame), mode
    OUT.zarr/zarr.json             --> attributes "volanim" (origin_xyz: 3 numbers; a colour sequence's palette:
                                       256 [r, g, b]) and "ome" (time scale > 0)
    OUT.zarr/0/zarr.json           --> the array: (T = frames, Z, Y, X) sizes >= 1 that fit in memory, its
                                       chunks no larger than a frame, a dtype volanim writes
    OUT.zarr/volanim-frames.jsonl  --> the finished frames' records (index, sha256, region, box, ...)
                          |
                          v
    Store (frozen) --read_part(index)--> the frame's recorded region and its corner, its sha256 compared
                   --read_frame(index)--> the frame on the whole shared grid (when that fits in memory)

Every check refuses with a FormatError naming the store's file and, for the manifest, its line.
The fault corpus found 29 crashes and 9 memory blow-ups where this metadata was indexed unchecked
(a plan that is a list, an OME time scale of 0, a plan claiming 10^12 frames, an array claiming
2 x 10^15 voxels), and frames whose shard was gone or swapped drawn as if nothing were wrong.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io.files import load_json, parse_json, regular_file_bytes, resolved
from volanim_core.limits import MAX_AXIS, checked_grid
from volanim_core.modes import MODES

PLAN_FILE, FRAMES_FILE = "volanim-plan.json", "volanim-frames.jsonl"
MAX_FRAMES = 1_000_000
MAX_MANIFEST_BYTES = 4096 * MAX_FRAMES  # a record is ~400 bytes
DTYPES = ("uint8", "uint16", "int16", "uint32", "int32", "float32")  # what output_dtype makes
_SHA256 = re.compile(r"[0-9a-f]{64}")


@dataclass(frozen=True)
class Store:
    path: Path
    key: str
    numbers: tuple[int, ...]  # one per frame
    mode: str | None
    shape_zyx: tuple[int, int, int]
    dtype: np.dtype
    origin_xyz: tuple[int, int, int]
    seconds_per_frame: float
    done: dict  # index -> its manifest record, for every frame recorded complete
    palette: np.ndarray | None = None  # a colour sequence's (256, 3) uint8 colours, one per index; else None

    @property
    def frames(self) -> int:
        return len(self.numbers)

    def read_frame(self, index: int, verify: bool = True) -> np.ndarray:
        """Frame ``index`` as ``[x, y, z]`` on the whole shared grid (refused naming the store when that grid
        does not fit in memory: :meth:`read_part` reads only the frame's body); with ``verify``, refused unless
        it hashes to its record's sha256 (a missing or swapped shard, a changed file)."""
        checked_grid(self.path, self.shape_zyx[::-1], self.dtype.itemsize, what="the sequence's shared grid")
        part, corner = self.read_part(index, verify)
        whole = np.zeros(self.shape_zyx[::-1], self.dtype)
        whole[tuple(slice(c, c + n) for c, n in zip(corner, part.shape))] = part
        return whole

    def read_part(self, index: int, verify: bool = True) -> tuple[np.ndarray, tuple[int, int, int]]:
        """Frame ``index``'s recorded region as ``[x, y, z]`` and its corner ``(x, y, z)`` in the grid's voxels;
        outside the region the frame is empty. A walk's shared grid is mostly empty (the full-size walk's is
        31.5 G voxels, a frame's region 0.4 G): renders and viewers read this. With ``verify``, refused unless it
        hashes to its record's sha256. A frame recorded before regions were (no ``"region"``) is read whole and
        cannot be verified; an empty frame is one empty voxel at the corner."""
        import zarr

        from .store import frame_checksum

        if not 0 <= index < self.frames:
            raise FormatError(self.path, f"has no frame at index {index} (it has {self.frames})")
        rec = self.done.get(index)
        known = rec is not None and rec.get("region") is not None
        region = tuple(slice(a, b) for a, b in rec["region"]) if known else \
            tuple(slice(0, n) for n in self.shape_zyx)
        sizes = [s.stop - s.start for s in region]
        if min(sizes) > 0:  # a region that does not fit in memory is refused before zarr allocates it
            checked_grid(self.path, sizes[::-1], self.dtype.itemsize, what=f"frame {self.numbers[index]}'s region")
        array = zarr.open_array(str(self.path / "0"), mode="r")
        try:
            zyx = np.asarray(array[(index, *region)])
        except MemoryError:
            raise
        except Exception as exc:  # noqa: BLE001 - zarr's codecs raise RuntimeError, ValueError, ... for a bad shard
            shard = f"0/c/{index // (array.shards or array.chunks)[0]}/"
            raise FormatError(self.path, f"frame {self.numbers[index]} (index {index}): its shard {shard} cannot be "
                                         f"decoded ({type(exc).__name__}: {exc}): the file was damaged or changed "
                                         "after it was written; rerun `volanim sequence` with --force to make "
                                         "it again") from exc
        if verify and known and frame_checksum(zyx, region) != rec["sha256"]:
            raise FormatError(self.path, f"frame {self.numbers[index]} (index {index}) does not match its "
                              f"sha256 in {FRAMES_FILE}: its shard in 0/ is missing or was changed; "
                              "rerun `volanim sequence` with --force to make it again")
        if not zyx.size:
            return np.zeros((1, 1, 1), self.dtype), (0, 0, 0)
        return zyx.T, tuple(int(s.start) for s in region[::-1])

    def read_colour(self, index: int) -> np.ndarray:
        """A colour sequence's frame ``index`` as ``[x, y, z, 3]`` colours: its indices through its palette."""
        if self.palette is None:
            raise ValueError(f"{self.path} is not a colour sequence (it has no palette)")
        return self.palette[self.read_frame(index)]

    def read_colour_part(self, index: int) -> tuple[np.ndarray, tuple[int, int, int]]:
        """:meth:`read_part` of a colour sequence, in colours ``[x, y, z, 3]``."""
        if self.palette is None:
            raise ValueError(f"{self.path} is not a colour sequence (it has no palette)")
        part, corner = self.read_part(index)
        return self.palette[part], corner

    def verified(self, index: int) -> bool:
        """Whether :meth:`read_frame` can verify this frame (its record has the region it hashed)."""
        rec = self.done.get(index)
        return rec is not None and rec.get("region") is not None


def _need(path, ok: bool, message: str, line: int | None = None) -> None:
    if not ok:
        raise FormatError(path, message, line)


def _int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _number(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


_CACHE: dict = {}  # path -> (the metadata files' sizes and times, Store): a movie reads every frame


def read_store(path) -> Store:
    """Check a sequence store's metadata (see the module docstring); FormatError naming the file and key.
    Checked once while its files are unchanged."""
    path = resolved(path)
    stamp = []
    for name in (PLAN_FILE, "zarr.json", "0/zarr.json", FRAMES_FILE):
        try:
            st = (path / name).stat()
            stamp.append((st.st_size, st.st_mtime_ns))
        except OSError:
            stamp.append(None)
    hit = _CACHE.get(path)
    if hit is not None and hit[0] == stamp:
        return hit[1]
    store = _read_store(path)
    if len(_CACHE) > 16:
        _CACHE.clear()
    _CACHE[path] = (stamp, store)
    return store


def _read_store(path: Path) -> Store:
    plan_file = path / PLAN_FILE
    if not plan_file.is_file():
        raise FormatError(path, f"is not a volanim sequence (no {PLAN_FILE}): make one with `volanim sequence`")
    plan = load_json(plan_file, what="sequence plan")
    _need(plan_file, isinstance(plan, dict), "must be a JSON object (the sequence's plan)")
    key, frames, numbers, mode = plan.get("key"), plan.get("frames"), plan.get("numbers"), plan.get("mode")
    _need(plan_file, isinstance(key, str) and 0 < len(key) <= 256, f"\"key\" must be the plan's hash, got {key!r}")
    _need(plan_file, _int(frames) and 1 <= frames <= MAX_FRAMES,
          f"\"frames\" must be a whole number 1..{MAX_FRAMES:,}, got {frames!r}")
    _need(plan_file, isinstance(numbers, list) and len(numbers) == frames and all(
        _int(n) and abs(n) < 2**31 for n in numbers), f"\"numbers\" must be {frames} frame numbers")
    _need(plan_file, mode is None or mode in MODES, f"\"mode\" must be one of {', '.join(MODES)}, got {mode!r}")

    group_file = path / "zarr.json"
    group = load_json(group_file, what="zarr group")
    attrs = group.get("attributes") if isinstance(group, dict) else None
    _need(group_file, isinstance(attrs, dict), "must be a zarr group with \"attributes\"")
    ours = attrs.get("volanim")
    _need(group_file, isinstance(ours, dict), "\"attributes\" lack \"volanim\" (written by `volanim sequence`)")
    origin = ours.get("origin_xyz")
    _need(group_file, isinstance(origin, list) and len(origin) == 3 and all(
        _number(v) and abs(v) < 2**31 for v in origin),
        f"\"volanim\": \"origin_xyz\" must be 3 numbers, got {origin!r}")
    palette = ours.get("palette")
    _need(group_file, palette is None or (isinstance(palette, list) and len(palette) == 256 and all(
        isinstance(c, list) and len(c) == 3 and all(_int(v) and 0 <= v <= 255 for v in c) for c in palette)),
        "\"volanim\": \"palette\" must be 256 colours [r, g, b] of 0..255")
    try:
        scale = attrs["ome"]["multiscales"][0]["datasets"][0]["coordinateTransformations"][0]["scale"]
    except (KeyError, IndexError, TypeError):
        raise FormatError(group_file, "\"attributes\" lack the OME-Zarr \"ome\" multiscales scale "
                                      "(datasets[0].coordinateTransformations[0].scale)") from None
    # a spatial scale may be negative: an axis that runs against its physical one (store.ome_scale)
    _need(group_file, isinstance(scale, list) and len(scale) == 4 and all(_number(v) and v != 0 for v in scale)
          and scale[0] > 0, f"the OME scale must be 4 numbers (t, z, y, x), time positive, none zero, got {scale!r}")

    array_file = path / "0" / "zarr.json"
    array = load_json(array_file, what="zarr array")
    shape = array.get("shape") if isinstance(array, dict) else None
    _need(array_file, isinstance(shape, list) and len(shape) == 4 and all(_int(n) for n in shape),
          f"\"shape\" must be 4 whole numbers (t, z, y, x), got {shape!r}")
    _need(array_file, shape[0] == frames, f"\"shape\" holds {shape[0]} frames, the plan {frames}")
    dtype = array.get("data_type")
    _need(array_file, dtype in DTYPES, f"\"data_type\" must be one of {', '.join(DTYPES)}, got {dtype!r}")
    _need(array_file, palette is None or dtype == "uint8", f"a colour sequence's \"data_type\" is uint8 (palette "
          f"indices), got {dtype!r}")
    # the shared grid need not fit in memory (a full-size walk's is 31.5 G voxels): a frame's region must,
    # checked where it is read (Store.read_part); the whole grid only where it is asked for (read_frame)
    z, y, x = checked_grid(array_file, shape[:0:-1], np.dtype(dtype).itemsize, what="\"shape\"",
                           allocate=False)[::-1]
    for where, chunks in _chunk_shapes(array):
        _need(array_file, isinstance(chunks, list) and len(chunks) == 4 and all(
            _int(c) and 1 <= c <= min(MAX_AXIS, 2 * max(n, 128)) for c, n in zip(chunks, [1, z, y, x])),
            f"{where} must be 4 sizes no larger than a frame's, got {chunks!r}")
    return Store(path, key, tuple(numbers), mode, (z, y, x), np.dtype(dtype), tuple(int(v) for v in origin),
                 float(scale[0]), _manifest(path, frames, (z, y, x)),
                 None if palette is None else np.asarray(palette, np.uint8))


def _chunk_shapes(array: dict):
    """Every chunk shape the array's metadata claims (its grid's, and a sharding codec's inner chunks)."""
    grid = array.get("chunk_grid")
    yield "\"chunk_grid\"", grid.get("configuration", {}).get("chunk_shape") if isinstance(grid, dict) else None
    for codec in array.get("codecs") or []:
        if isinstance(codec, dict) and codec.get("name") == "sharding_indexed":
            yield "the sharding codec's \"chunk_shape\"", (codec.get("configuration") or {}).get("chunk_shape")


def _manifest(path: Path, frames: int, shape_zyx) -> dict:
    """Index -> record of every finished frame. A last line without its newline is one a kill cut short
    (ignored); any other line that is not a record is refused, naming its line."""
    file = path / FRAMES_FILE
    if not file.exists():
        return {}
    lines = regular_file_bytes(file, MAX_MANIFEST_BYTES, "frame manifest").split(b"\n")
    done = {}
    for number, raw in enumerate(lines[:-1], start=1):  # lines[-1]: after the last newline (torn, or empty)
        if not raw.strip():
            continue
        rec = parse_json(file, raw)
        index = rec.get("index") if isinstance(rec, dict) else None
        _need(file, _int(index) and 0 <= index < frames, f"a record's \"index\" must be 0..{frames - 1}", number)
        _need(file, isinstance(rec.get("sha256"), str) and _SHA256.fullmatch(rec["sha256"]) is not None,
              "a record's \"sha256\" must be 64 hex digits", number)
        region = rec.get("region")
        _need(file, region is None or (isinstance(region, list) and len(region) == 3 and all(
            isinstance(r, list) and len(r) == 2 and all(_int(v) for v in r) and 0 <= r[0] <= r[1] <= n
            for r, n in zip(region, shape_zyx))), "a record's \"region\" must be 3 [start, stop] in the grid", number)
        box = rec.get("box")
        _need(file, box is None or (isinstance(box, list) and len(box) == 2 and all(
            isinstance(b, list) and len(b) == 3 and all(_int(v) and abs(v) < 2**31 for v in b) for b in box)),
            "a record's \"box\" must be [[x, y, z], [x, y, z]]", number)
        hot = rec.get("hotspot_max")
        _need(file, hot is None or (_number(hot) and hot >= 0), "a record's \"hotspot_max\" must be a number >= 0",
              number)
        done[index] = rec
    return done
