"""BVH motion capture: the reader and forward kinematics over every frame at once.

    HIERARCHY
    ROOT Hips { OFFSET x y z  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
                JOINT Spine { OFFSET ...  CHANNELS 3 ...  End Site { OFFSET ... } } }
    MOTION
    Frames: N
    Frame Time: dt
    N lines of one number per channel, in the order the hierarchy lists them

Conventions (the BVH de-facto standard, as Blender and MotionBuilder read it):
each joint's rotation channels are Euler angles in degrees applied *intrinsically
in the listed order*, ``R = R1 @ R2 @ R3`` on column vectors (scipy's upper-case
axis sequence); a joint's local translation is its OFFSET plus its position
channels (root and any 6-channel joint); ``world_rot[j] = world_rot[parent] @
local_rot[j]`` and ``world_pos[j] = world_pos[parent] + world_rot[parent] @
local_pos[j]``. Units are whatever the file uses; ``scale`` converts them.

Parsing keeps line numbers (errors name the file and line); the hierarchy is
walked with an explicit stack (no recursion on file depth) and the motion block
is converted in one NumPy call.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io.text import is_number
from volanim_core.limits import available_bytes, human_bytes

MAX_JOINTS = 10_000
# Offsets, positions and angles beyond this are no capture (a billion millimetres is 1000 km; a billion
# degrees turns nothing sensibly): 1e308 overflowed forward kinematics, 1e20 no coordinate can hold
MAX_VALUE = 1e9
_AXES = {"xrotation": "X", "yrotation": "Y", "zrotation": "Z"}
_POSITIONS = {"xposition": 0, "yposition": 1, "zposition": 2}


@dataclass
class Motion:
    """A BVH clip: joints in file order (parents before children) and per-frame channel values."""

    names: list[str]
    parents: np.ndarray  # (J,) int, -1 for the root
    offsets: np.ndarray  # (J, 3) rest offset from the parent, file units
    channels: list[list[str]]  # per joint, lower-case channel names in file order
    frame_time: float
    values: np.ndarray  # (F, C) float64, C = total channel count
    end_sites: dict[int, np.ndarray] = field(default_factory=dict)  # joint -> End Site offset
    animation: str | None = None  # which of the file's animations (glTF holds several; BVH one: None)

    def __post_init__(self) -> None:
        """A Motion made in code is held to what a file is (ValueError): the API took NaN values, a joint
        cycle (forward kinematics then returned uninitialised numbers) and a wrong-width value array."""
        n = len(self.names)
        self.parents = np.asarray(self.parents, np.int64).reshape(-1)
        self.offsets = np.asarray(self.offsets, np.float64).reshape(-1, 3) if n else np.zeros((0, 3))
        self.values = np.asarray(self.values, np.float64)
        if not 0 < n <= MAX_JOINTS or len(set(self.names)) != n:
            raise ValueError(f"a motion needs 1..{MAX_JOINTS} joints with distinct names, got {n}")
        if len(self.parents) != n or len(self.offsets) != n or len(self.channels) != n:
            raise ValueError(f"{n} joints need {n} parents, offsets and channel lists")
        if self.parents[0] != -1 or any(not -1 <= p < j for j, p in enumerate(self.parents)):
            raise ValueError("parents must come before their children (file order): a joint's parent index is "
                             "-1 (a root) or smaller than its own; a cycle has no such order")
        for chans in self.channels:
            unknown = [c for c in chans if c not in _AXES and c not in _POSITIONS]
            if unknown:
                raise ValueError(f"unknown channel {unknown[0]!r}: channels are X/Y/Z position and rotation")
        width = sum(len(c) for c in self.channels)
        if self.values.ndim != 2 or self.values.shape[1] != width:
            raise ValueError(f"values must be (frames, {width}) for these channels, got {self.values.shape}")
        for what, a in (("values", self.values), ("offsets", self.offsets)):
            if not (np.abs(a) <= MAX_VALUE).all():
                raise ValueError(f"{what} must be finite numbers of at most {MAX_VALUE:g}")
        if not (np.isfinite(self.frame_time) and self.frame_time > 0):
            raise ValueError(f"the frame time must be a positive number, got {self.frame_time!r}")

    @property
    def frames(self) -> int:
        return len(self.values)

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time if self.frame_time > 0 else 0.0

    def index(self, name: str) -> int:
        """The joint's index; ValueError naming the clip's joints when it has none of that name."""
        try:
            return self.names.index(name)
        except ValueError:
            shown = ", ".join(self.names[:12]) + (", ..." if len(self.names) > 12 else "")
            raise ValueError(f"no joint named {name!r} in the clip; it has {shown}") from None

    def rest_positions(self) -> np.ndarray:
        """``(J, 3)`` joint positions with every channel zero (the clip's rest pose, often a T-pose)."""
        pos = np.zeros((len(self.names), 3))
        for j, p in enumerate(self.parents):
            pos[j] = self.offsets[j] + (pos[p] if p >= 0 else 0.0)
        return pos

    def rest_points(self) -> np.ndarray:
        """Rest positions of the joints and of the End Sites (the clip's extent)."""
        rest = self.rest_positions()
        ends = [rest[j] + off for j, off in self.end_sites.items()]
        return np.vstack([rest, *ends]) if ends else rest

    def is_descendant(self, j: int, k: int) -> bool:
        """Whether joint ``j`` hangs (at any depth) from joint ``k``."""
        while j >= 0:
            j = int(self.parents[j])
            if j == k:
                return True
        return False

    def child_directions(self, k: int) -> list[np.ndarray]:
        """Rest offsets of joint ``k``'s children, or of its End Site: where its bone points."""
        kids = [self.offsets[j] for j in np.flatnonzero(self.parents == k)]
        if kids:
            return [max(kids, key=np.linalg.norm)]  # the longest: the limb, not a side branch
        return [self.end_sites[k]] if k in self.end_sites else []

    def local_transforms(self, frames=slice(None)) -> tuple[np.ndarray, np.ndarray]:
        """``(rotations (F, J, 3, 3), translations (F, J, 3))`` of every joint relative to its parent."""
        vals = self.values[frames]
        n = len(vals)
        rot = np.broadcast_to(np.eye(3), (n, len(self.names), 3, 3)).copy()
        pos = np.broadcast_to(self.offsets, (n, len(self.names), 3)).copy()
        column = 0
        for j, chans in enumerate(self.channels):
            axes, cols = "", []
            moves = [(column + k, _POSITIONS[c]) for k, c in enumerate(chans) if c not in _AXES]
            if moves and j in self.absolute_positions:
                for col, axis in moves:
                    pos[:, j, axis] = vals[:, col]
                moves = []
            for col, axis in moves:
                pos[:, j, axis] += vals[:, col]
            for k, c in enumerate(chans):
                if c in _AXES:
                    axes += _AXES[c]
                    cols.append(column + k)
            if axes:
                rot[:, j] = euler_matrices(axes, vals[:, cols])
            column += len(chans)
        return rot, pos

    @cached_property
    def absolute_positions(self) -> frozenset[int]:
        """Non-root joints whose position channels hold their whole local position, not a move from it.

        **Decided here** (docs/formats.md, BVH): BVH leaves a child's position channels undefined.
        Blender writes them as the joint's local position (equal to its OFFSET while it does not
        move) and reads them so; three.js adds them to the OFFSET. Read both ways, a Blender clip
        with 6-channel joints doubles every bone that has them. So a joint's channels replace its
        OFFSET when they lie nearer the OFFSET than zero (median over the frames), and add to it
        otherwise. The root is always a move (only its displacement is used).
        """
        found, column = set(), 0
        for j, chans in enumerate(self.channels):
            cols = [(column + k, _POSITIONS[c]) for k, c in enumerate(chans) if c in _POSITIONS]
            column += len(chans)
            if j == 0 or not cols or not len(self.values):
                continue
            v = self.values[:, [c for c, _ in cols]]
            off = self.offsets[j, [a for _, a in cols]]
            if np.median(np.linalg.norm(v - off, axis=1)) < np.median(np.linalg.norm(v, axis=1)):
                found.add(j)
        return frozenset(found)

    def forward_kinematics(self, frames=slice(None), scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """World ``(rotations (F, J, 3, 3), positions (F, J, 3))`` of every joint, positions times ``scale``."""
        rot, pos = self.local_transforms(frames)
        world_rot = np.empty_like(rot)
        world_pos = np.empty_like(pos)
        for j, p in enumerate(self.parents):  # parents come first in file order
            if p < 0:
                world_rot[:, j] = rot[:, j]
                world_pos[:, j] = pos[:, j]
            else:
                world_rot[:, j] = world_rot[:, p] @ rot[:, j]
                world_pos[:, j] = world_pos[:, p] + (world_rot[:, p] @ pos[:, j, :, None])[..., 0]
        return world_rot, world_pos * scale


def euler_matrices(axes: str, degrees: np.ndarray) -> np.ndarray:
    """``(F, 3, 3)`` rotations of intrinsic Euler angles (BVH's channel order, e.g. ``"ZXY"``): the product of
    the axes' rotations in that order, as scipy's ``Rotation.from_euler(axes, degrees, degrees=True)`` makes
    them (the tests compare the two). Written out because scipy 1.17's took 2.4 ms a joint of a 1064-frame clip:
    56 of the 75 ms a clip's forward kinematics took, on the studio's GUI thread while a clip loads."""
    angles = np.radians(np.asarray(degrees, np.float64).reshape(len(degrees), len(axes)))
    out = None
    for k, axis in enumerate(axes):
        c, s = np.cos(angles[:, k]), np.sin(angles[:, k])
        m = np.zeros((len(angles), 3, 3))
        i, j = {"X": (1, 2), "Y": (2, 0), "Z": (0, 1)}[axis]  # the plane the axis turns: i -> j
        m[:, "XYZ".index(axis), "XYZ".index(axis)] = 1.0
        m[:, i, i] = m[:, j, j] = c
        m[:, i, j], m[:, j, i] = -s, s
        out = m if out is None else out @ m
    return out


def _tokens(text: str):
    for number, line in enumerate(text.splitlines(), start=1):
        for tok in line.split():
            yield number, tok


def read_bvh(path: str | Path) -> Motion:
    """Read a BVH file; a bad one is a :class:`FormatError` naming the file and line."""
    from volanim_core.io.files import regular_file_bytes
    from volanim_core.io.text import MAX_TEXT_BYTES

    path = Path(path)
    raw = regular_file_bytes(path, MAX_TEXT_BYTES, "BVH file")
    if b"\0" in raw:
        line = raw[:raw.index(b"\0")].count(b"\n") + 1
        raise FormatError(path, "holds a NUL byte: a binary file, expected BVH text", line)
    try:
        text = raw.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError:
        raise FormatError(path, "not UTF-8 text, expected a BVH file") from None
    found = re.search(r"^[ \t]*MOTION[ \t]*\r?$", text, re.MULTILINE)
    if found is None:
        raise FormatError(path, "no MOTION section: expected HIERARCHY ... MOTION ... Frames: ... Frame Time: ...")
    head, motion_text = text[: found.start()], text[found.end():]
    motion_line = head.count("\n") + 1  # motion_text's first (empty) line is the MOTION line's end
    names, parents, offsets, channels, end_sites = _hierarchy(path, head)
    frame_time, values = _motion(path, motion_text, motion_line, sum(len(c) for c in channels))
    return Motion(names, np.array(parents, np.int64), np.array(offsets, np.float64).reshape(-1, 3), channels,
                  frame_time, values, end_sites)


def _number(path, line: int, tok: str, what: str) -> float:
    if not is_number(tok):
        raise FormatError(path, f"expected a number for {what}, got {tok!r}", line)
    value = float(tok)
    if not np.isfinite(value) or abs(value) > MAX_VALUE:
        raise FormatError(path, f"expected a finite number of at most {MAX_VALUE:g} for {what}, got {tok!r}", line)
    return value


def _hierarchy(path, text: str):
    toks = list(_tokens(text))
    if not toks or toks[0][1] != "HIERARCHY":
        raise FormatError(path, "expected a BVH file starting with HIERARCHY", toks[0][0] if toks else 1)
    names, parents, offsets, channels, end_sites = [], [], [], [], {}
    stack: list[int] = []  # open joints; -2 marks an open End Site
    i = 1

    def take(what: str) -> tuple[int, str]:
        nonlocal i
        if i >= len(toks):
            raise FormatError(path, f"the hierarchy ends early: expected {what}", toks[-1][0])
        i += 1
        return toks[i - 1]

    def offset(owner: str) -> list[float]:
        line, tok = take("OFFSET")
        if tok != "OFFSET":
            raise FormatError(path, f"expected 'OFFSET x y z' in {owner}, got {tok!r}", line)
        return [_number(path, *take("an offset"), f"the OFFSET of {owner}") for _ in range(3)]

    while i < len(toks):
        line, tok = take("a joint")
        if tok in ("ROOT", "JOINT"):
            if tok == "ROOT" and (stack or names):
                raise FormatError(path, "a second ROOT: volanim reads one skeleton per file", line)
            if tok == "JOINT" and not stack:
                raise FormatError(path, "JOINT outside the ROOT's braces", line)
            if stack and stack[-1] == -2:
                raise FormatError(path, "a JOINT inside an End Site", line)
            if len(names) >= MAX_JOINTS:
                raise FormatError(path, f"more than {MAX_JOINTS} joints", line)
            name_line, name = take("a joint name")
            while i < len(toks) and toks[i][0] == name_line and toks[i][1] != "{":  # "Bip01 L Thigh": a name
                name += " " + take("a joint name")[1]  # with spaces, as 3ds Max writes and Blender reads it
            if name in names:
                raise FormatError(path, f"joint {name!r} is defined twice", line)
            brace = take("'{'")
            if brace[1] != "{":
                raise FormatError(path, f"expected '{{' after {tok} {name}, got {brace[1]!r}", brace[0])
            names.append(name)
            parents.append(stack[-1] if stack else -1)
            offsets.append(offset(name))
            cl, ctok = take("CHANNELS")
            if ctok != "CHANNELS":
                raise FormatError(path, f"expected 'CHANNELS n ...' for {name}, got {ctok!r}", cl)
            nl, ntok = take("a channel count")
            if ntok not in ("0", "3", "6"):
                raise FormatError(path, f"CHANNELS of {name} must be 0, 3 or 6, got {ntok!r}", nl)
            chans = [take("a channel name") for _ in range(int(ntok))]
            bad = [(ln, c) for ln, c in chans if c.lower() not in (*_AXES, *_POSITIONS)]
            if bad:
                raise FormatError(path, f"unknown channel {bad[0][1]!r} (expected Xposition..Zrotation)", bad[0][0])
            lowered = [c.lower() for _, c in chans]
            if len(set(lowered)) != len(lowered):
                raise FormatError(path, f"{name} lists a channel twice: {' '.join(lowered)}", cl)
            channels.append(lowered)
            stack.append(len(names) - 1)
        elif tok == "End":
            site = take("Site")
            brace = take("'{'")
            if site[1] != "Site" or brace[1] != "{" or not stack or stack[-1] < 0:
                raise FormatError(path, "expected 'End Site {' inside a joint", line)
            end_sites[stack[-1]] = np.array(offset(f"the End Site of {names[stack[-1]]}"))
            stack.append(-2)
        elif tok == "}":
            if not stack:
                raise FormatError(path, "'}' without a matching '{'", line)
            stack.pop()
            if not stack and i < len(toks):
                raise FormatError(path, f"text after the ROOT's closing brace: {toks[i][1]!r}", toks[i][0])
        else:
            raise FormatError(path, f"expected JOINT, End Site or '}}', got {tok!r}", line)
    if stack:
        raise FormatError(path, f"the hierarchy ends with {len(stack)} unclosed '{{'", toks[-1][0])
    if not names:
        raise FormatError(path, "the hierarchy has no ROOT joint", toks[0][0])
    return names, parents, offsets, channels, end_sites


def _motion(path, text: str, first_line: int, n_channels: int) -> tuple[float, np.ndarray]:
    lines = text.splitlines()
    rows = [(first_line + k, ln) for k, ln in enumerate(lines, start=0) if ln.strip()]
    if len(rows) < 2:
        raise FormatError(path, "the MOTION section needs 'Frames: N' and 'Frame Time: T'", first_line)
    (fl, frames_line), (tl, time_line) = rows[0], rows[1]
    m = re.fullmatch(r"\s*Frames:\s*([0-9]+)\s*", frames_line)
    if not m:
        raise FormatError(path, f"expected 'Frames: N', got {frames_line.strip()!r}", fl)
    n_frames = int(m.group(1))
    m = re.fullmatch(r"\s*Frame Time:\s*(\S+)\s*", time_line)
    if not m:
        raise FormatError(path, f"expected 'Frame Time: T', got {time_line.strip()!r}", tl)
    frame_time = _number(path, tl, m.group(1), "the frame time")
    if frame_time <= 0:
        raise FormatError(path, f"the frame time must be positive, got {m.group(1)}", tl)
    data = rows[2:]
    need = n_frames * max(n_channels, 1) * 8
    free = available_bytes()
    if free is not None and need > free:
        raise FormatError(path, f"claims {n_frames} frames ({human_bytes(need)}), more than the memory free", fl)
    if len(data) != n_frames:
        where = data[n_frames][0] if len(data) > n_frames else (data[-1][0] if data else tl)
        raise FormatError(path, f"'Frames: {n_frames}' but the file has {len(data)} frame lines", where)
    chars = set("".join(ln for _, ln in data))
    values = None
    if chars <= set("0123456789+-.eE \t\r"):
        try:
            values = np.array([ln.split() for _, ln in data], np.float64).reshape(n_frames, n_channels)
        except ValueError:
            values = None
    if values is None or not (np.abs(values) <= MAX_VALUE).all():  # find the first bad line (NaN fails too)
        for line, ln in data:
            toks = ln.split()
            if len(toks) != n_channels:
                raise FormatError(path, f"expected {n_channels} channel values, got {len(toks)}", line)
            for tok in toks:
                _number(path, line, tok, "a channel value")
        raise FormatError(path, "bad channel values", data[0][0] if data else tl)
    return frame_time, values
