"""Meshes checked before VTK sees them: every count a header claims, every face's corners and indices.

    .ply  header --> elements and properties --> the body walked (ASCII lines, or binary records):
          counts the file cannot hold, list counts over MAX_CORNERS, a face naming a vertex it does not have,
          no faces at all: FormatError; then VTK reads it
    .obj  read here (VTK never parses it): v and f lines, relative (negative) indices resolved, each index
          checked, faces of 3..MAX_CORNERS corners --> pyvista PolyData

The fault corpus made VTK segfault on a face naming vertex 99999999 of 4 or a negative index, abort on
a binary face list count of 2^32 - 1, accept a PLY claiming 3000 vertices that holds 4, and hang on an
OBJ face of 900 000 corners.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.limits import MAX_MEASURE

MAX_CORNERS = 1024  # corners of one polygon (VTK triangulates it: a 900 000-corner face hung)
MAX_HEADER = 1 << 16
MAX_LINE = 1 << 20  # an OBJ line: a face of MAX_CORNERS corners is some 20 KB
_PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
              "float": "f4", "float32": "f4", "double": "f8", "float64": "f8"}


def check_ply(path: Path) -> None:
    """Refuse a PLY whose body does not hold what its header claims, or whose faces are not faces."""
    data = path.read_bytes()
    end = data.find(b"end_header", 0, MAX_HEADER)
    if not data.startswith(b"ply") or end < 0:
        raise FormatError(path, "is not a PLY file (it must start with 'ply' and have an end_header)")
    body = data.index(b"\n", end) + 1 if b"\n" in data[end:end + 64] else len(data)
    fmt, elements = _ply_header(path, data[:end].decode("latin-1"))
    names = [e[0] for e in elements]
    if "vertex" not in names:
        raise FormatError(path, "has no vertex element")
    faces = next((e for e in elements if e[0] == "face"), None)
    if faces is None or faces[1] == 0:
        raise FormatError(path, "holds no faces: a surface is needed")
    n_vertices = elements[names.index("vertex")][1]
    if fmt == "ascii":
        _walk_ascii(path, data[body:], elements, n_vertices)
    else:
        _walk_binary(path, data, body, elements, n_vertices, "<" if fmt == "binary_little_endian" else ">")


def _ply_header(path, text: str):
    fmt, elements = None, []
    for number, line in enumerate(text.splitlines(), start=1):
        words = line.split()
        if not words or words[0] in ("ply", "comment", "obj_info"):
            continue
        if words[0] == "format" and len(words) >= 2:
            fmt = words[1]
        elif words[0] == "element" and len(words) == 3 and words[2].isascii() and words[2].isdigit():
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property" and elements and len(words) == 3 and words[1] in _PLY_TYPES:
            elements[-1][2].append((words[2], None, _PLY_TYPES[words[1]]))
        elif (words[0] == "property" and elements and len(words) == 5 and words[1] == "list"
              and words[2] in _PLY_TYPES and words[3] in _PLY_TYPES):
            elements[-1][2].append((words[4], _PLY_TYPES[words[2]], _PLY_TYPES[words[3]]))
        else:
            raise FormatError(path, f"PLY header line not understood: {line[:80]!r}", number)
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise FormatError(path, f"unknown PLY format {fmt!r}")
    return fmt, elements


def _check_face(path, count: int, indices, n_vertices: int, record: int, line: int | None = None) -> None:
    if not 3 <= count <= MAX_CORNERS:
        raise FormatError(path, f"face {record} has {count} corners; faces have 3..{MAX_CORNERS}", line)
    bad = [int(i) for i in indices if not 0 <= int(i) < n_vertices]
    if bad:
        raise FormatError(path, f"face {record} names vertex {bad[0]}; the file has {n_vertices} vertices", line)


def _whole(path, word: str, what: str) -> int:
    try:
        value = float(word)
    except ValueError:
        raise FormatError(path, f"{what}: expected a number, got {word[:20]!r}") from None
    if not value.is_integer():
        raise FormatError(path, f"{what}: expected a whole number, got {word[:20]!r}")
    return int(value)


def _walk_ascii(path, body: bytes, elements, n_vertices: int) -> None:
    lines = [ln for ln in body.decode("latin-1").splitlines() if ln.strip() and not ln.startswith("comment")]
    at = 0
    for name, count, props in elements:
        if at + count > len(lines):
            raise FormatError(path, f"claims {count} {name} elements; the file holds {max(len(lines) - at, 0)}")
        for k in range(count):
            words = lines[at + k].split()
            pos = 0
            for prop, count_type, _ in props:
                if count_type is None:
                    pos += 1
                    continue
                n = _whole(path, words[pos], f"{name} {k}'s list count") if pos < len(words) else -1
                if not 0 <= n <= MAX_CORNERS or pos + 1 + n > len(words):
                    raise FormatError(path, f"{name} {k}: a list of {n} values does not fit its line")
                if name == "face" and prop in ("vertex_indices", "vertex_index"):
                    _check_face(path, n, [_whole(path, w, f"face {k}'s index") for w in words[pos + 1:pos + 1 + n]],
                                n_vertices, k)
                pos += 1 + n
            if pos > len(words):
                raise FormatError(path, f"{name} {k} has {len(words)} values; its properties need {pos}")
        at += count


def _walk_binary(path, data: bytes, at: int, elements, n_vertices: int, order: str) -> None:
    for name, count, props in elements:
        if all(c is None for _, c, _ in props):  # fixed-size records
            size = sum(np.dtype(t).itemsize for *_, t in props) * count
            if at + size > len(data):
                raise FormatError(path, f"claims {count} {name} elements; the file ends {at + size - len(data)} "
                                        "bytes short of them")
            at += size
            continue
        at = _list_records(path, data, at, name, count, props, n_vertices, order)


def _list_records(path, data: bytes, at: int, name: str, count: int, props, n_vertices: int, order: str) -> int:
    """Walk ``count`` records with list properties; a uniform triangle or quad list is checked with numpy."""
    uniform = _uniform_faces(data, at, name, count, props, n_vertices, order)
    if uniform is not None:
        return _checked_uniform(path, *uniform)
    for k in range(count):
        for prop, count_type, item in props:
            if count_type is None:
                at += np.dtype(item).itemsize
                continue
            width = np.dtype(count_type).itemsize
            if at + width > len(data):
                raise FormatError(path, f"{name} {k}: the file ends inside it")
            n = int(np.frombuffer(data, order + count_type, 1, at)[0])
            at += width
            size = np.dtype(item).itemsize
            if not 0 <= n <= MAX_CORNERS or at + n * size > len(data):
                raise FormatError(path, f"{name} {k}: a list of {n} values (the file holds at most "
                                        f"{MAX_CORNERS} corners a face, and ends before them)")
            if name == "face" and prop in ("vertex_indices", "vertex_index"):
                _check_face(path, n, np.frombuffer(data, order + item, n, at), n_vertices, k)
            at += n * size
    return at


def _uniform_faces(data, at, name, count, props, n_vertices, order):
    if name != "face" or len(props) != 1 or props[0][1] is None:
        return None
    _, count_type, item = props[0]
    width, size = np.dtype(count_type).itemsize, np.dtype(item).itemsize
    if at + width > len(data):
        return None
    n = int(np.frombuffer(data, order + count_type, 1, at)[0])
    if not 3 <= n <= 4 or at + count * (width + n * size) > len(data):
        return None
    rec = np.dtype([("n", order + count_type), ("i", order + item, (n,))])
    faces = np.frombuffer(data, rec, count, at)
    if not (faces["n"] == n).all():
        return None
    return faces, n_vertices, at + count * rec.itemsize


def _checked_uniform(path, faces, n_vertices: int, end: int) -> int:
    idx = faces["i"].astype(np.int64)
    bad = np.flatnonzero(((idx < 0) | (idx >= n_vertices)).any(1))
    if len(bad):
        k = int(bad[0])
        _check_face(path, int(faces["n"][k]), idx[k], n_vertices, k)
    return end


_OBJ_INDEX = re.compile(r"[+-]?\d+")


def _lines(path: Path, chunk: int = 1 << 20):
    """The file's lines (latin-1), read a megabyte at a time: memory follows the mesh, not the file's size
    (a sparse 3 GB OBJ peaked at 6 GB read whole); a line longer than MAX_LINE is refused."""
    rest = b""
    number = 0
    with open(path, "rb") as fh:
        while block := fh.read(chunk):
            parts = (rest + block).split(b"\n")
            rest = parts.pop()
            for part in parts:
                number += 1
                yield part.decode("latin-1").rstrip("\r")
            if len(rest) > MAX_LINE:
                raise FormatError(path, f"line {number + 1} runs past {MAX_LINE:,} bytes: not an OBJ's line",
                                  number + 1)
    if rest:
        yield rest.decode("latin-1").rstrip("\r")


def read_obj(path: Path):
    """A Wavefront OBJ's vertices and polygon faces as a pyvista PolyData, every index checked."""
    import pyvista as pv

    vertices, cells = [], []
    for number, line in enumerate(_lines(path), start=1):
        words = line.split()
        if not words:
            continue
        if words[0] == "v":
            try:
                xyz = [float(w) for w in words[1:4]]
            except ValueError:
                raise FormatError(path, f"a vertex needs 3 numbers: {line[:80]!r}", number) from None
            if len(xyz) != 3 or not np.isfinite(xyz).all() or max(map(abs, xyz)) > MAX_MEASURE:
                raise FormatError(path, f"a vertex needs 3 finite numbers within {MAX_MEASURE:g}: {line[:80]!r}",
                                  number)
            vertices.append(xyz)
        elif words[0] == "f":
            corners = words[1:]
            if not 3 <= len(corners) <= MAX_CORNERS:
                raise FormatError(path, f"a face has {len(corners)} corners; faces have 3..{MAX_CORNERS}", number)
            face = []
            for w in corners:
                m = _OBJ_INDEX.match(w)
                i = int(m.group()) if m and len(m.group()) < 12 else 0
                k = i - 1 if i > 0 else len(vertices) + i  # OBJ: 1-based; negative counts back from the last
                if i == 0 or not 0 <= k < len(vertices):
                    raise FormatError(path, f"a face names vertex {w.split('/')[0]!r}; {len(vertices)} vertices "
                                            "come before it", number)
                face.append(k)
            cells.append([len(face), *face])
    if not cells:
        raise FormatError(path, "holds no faces: a surface is needed")
    flat = np.fromiter((v for c in cells for v in c), np.int64)
    return pv.PolyData(np.asarray(vertices, np.float64), flat)
