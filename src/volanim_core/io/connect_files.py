"""``.connect``, ``.trans`` and ``.tskel``: files organised by ``Root:`` lines.

    Root: px py pz :: dx dy dz [NAME]     starts bone b (root order)
    m00 m01 m02 m03   x4                  .trans / .tskel: bone b's matrix
    x y z dt [thinness]                   .connect / .tskel: bone b's points
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from volanim_core.rig.connectivity import BoneSegment, Connectivity, Trans, Tskel, close_floats
from volanim_core.rig.skinning import RIGID, Joints

from ._columns import format_point_rows, parse_point_rows
from .atomic import atomic_write_text
from .text import TextRecords, fmt_float, parse_float, parse_geometry, parse_header, parse_metric, read_records

ROOT_SYNTAX = "'Root: x y z :: x y z [NAME]'"


def _is_root(toks: list[str]) -> bool:
    return toks[0].lower().startswith("root:")


def _parse_root(rec: TextRecords, line: int, toks: list[str]) -> BoneSegment:
    first = toks[0]
    rest = ([first[5:]] if len(first) > 5 else []) + toks[1:]  # allow 'Root:212'
    if "::" not in rest:
        raise rec.error(line, f"'Root:' line has no '::' between the joints, expected {ROOT_SYNTAX}")
    k = rest.index("::")
    prox, tail = rest[:k], rest[k + 1 :]
    if len(prox) != 3 or len(tail) not in (3, 4):
        raise rec.error(line, f"expected {ROOT_SYNTAX}, got {' '.join(toks)!r}")
    p = [parse_float(rec, line, t, "proximal joint coordinate") for t in prox]
    d = [parse_float(rec, line, t, "distal joint coordinate") for t in tail[:3]]
    return BoneSegment(p, d, tail[3] if len(tail) == 4 else "")


def _format_root(b: BoneSegment) -> str:
    p = " ".join(fmt_float(v) for v in b.proximal)
    d = " ".join(fmt_float(v) for v in b.distal)
    return f"Root: {p} :: {d}" + (f" {b.name}" if b.name else "")


def _whole(token: str) -> bool:
    return token.lstrip("+-").isdigit()


def _refuse_a_point_as_row_4(rec: TextRecords, records, start: int, rows) -> None:
    """In a ``.tskel`` without ``# points:``, a 4th matrix row ``x y z 1`` of whole numbers may be the first
    point (dt 1) after a matrix of 3 rows (docs/formats.md, ``.tskel``): read as a translation, the point was
    silently gone (#89). The file's own writing tells them apart when rows 1-3 are written with decimals and
    row 4 is not (a point line); when all four are whole numbers nothing can, and the file is refused with
    what to add. A zero translation is read as one: no skeleton point lies at the grid's corner."""
    line, toks = records[start + 3]
    if not (all(_whole(t) for t in toks[:3]) and rows[3][3] == 1.0) or not any(rows[3][:3]):
        return
    above = [t for k in range(3) for t in records[start + k][1]]
    if all(_whole(t) for t in above):
        raise rec.error(line, f"'{' '.join(toks)}' may be this matrix's translation or, after a matrix of 3 rows, "
                              "a point x y z with dt 1; add a '# points: N' line (the number of point lines) to "
                              "the header to say which")
    raise rec.error(line, f"the matrix has 3 rows: '{' '.join(toks)}' is written as a point (whole numbers, where "
                          "the rows above it have decimals); expected 4 rows of 4 numbers")


def _parse_matrix(rec: TextRecords, records, start: int, root_line: int, *, points_follow: bool = False
                  ) -> np.ndarray:
    rows = []
    for k in range(4):
        if start + k >= len(records):
            raise rec.error(root_line, f"the matrix after this 'Root:' line has {k} rows, expected 4 rows of 4 numbers")
        line, toks = records[start + k]
        if _is_root(toks):
            raise rec.error(line, f"the matrix of the previous bone has {k} rows, expected 4 rows of 4 numbers")
        if len(toks) != 4:
            raise rec.error(line, f"expected matrix row {k + 1} of 4 (4 numbers), got {len(toks)} tokens")
        rows.append([parse_float(rec, line, t, f"matrix row {k + 1}") for t in toks])
    # Row-vector convention: the last column of an affine matrix is (0 0 0 1).
    # Checking it also catches a 3-row matrix swallowing the first point line.
    if not close_floats([r[3] for r in rows], (0.0, 0.0, 0.0, 1.0), 1e-6):
        line = records[start][0]
        raise rec.error(line, "matrix is not affine: its last column must be 0 0 0 1 "
                        "(row-vector convention, translation in row 4)")
    if points_follow and "points" not in rec.header:
        _refuse_a_point_as_row_4(rec, records, start, rows)
    return np.array(rows)


def _check_point_count(rec: TextRecords, found: int) -> None:
    """Compare with the ``# points: N`` header volanim writes, when the file has one.

    Why: in a ``.tskel`` a 3-row matrix followed by a point ``x y z 1`` reads
    exactly like a 4-row matrix whose translation is (x, y, z); only a count
    written beside the points tells the two apart (docs/formats.md, ``.tskel``).
    """
    text = rec.header.get("points")
    if text is None:
        return
    line = rec.header_lines.get("points")
    text = text.strip()
    if not (text.isascii() and text.isdigit()) or len(text) > 12:  # "²".isdigit() is True; int() refuses it
        raise rec.error(line, f"bad '# points: {text}' header, expected a whole number")
    if int(text) != found:
        raise rec.error(line, f"the header says {int(text)} points but the file has {found} point lines; "
                              "a line is missing or extra (a matrix of 3 rows takes the next point as its 4th)")


MAX_SCALE = 100.0  # a bone grown or shrunk a hundredfold is a unit mistake, not a pose


def _refuse_what_no_pose_does(rec, bones: list[BoneSegment], lines: list[int], mats: np.ndarray) -> None:
    """The first matrix that flattens its bone (singular) or scales it beyond ``MAX_SCALE``, refused at its first
    row's line. Why here: reconstruct found them later, naming neither the file's line nor what to do (a scale of
    1000 became "the output grid would be 1.1 PB"). All bones at once: a clip reads thousands of frames."""
    if not len(mats):
        return
    stretch = np.linalg.svd(mats[:, :3, :3], compute_uv=False)  # (n, 3), each bone's largest stretch first
    bad = np.flatnonzero((stretch[:, 0] > MAX_SCALE) | (stretch[:, 2] < 1 / MAX_SCALE))
    if not len(bad):
        return
    b = int(bad[0])
    largest, smallest = stretch[b, 0], stretch[b, 2]
    what = ("is singular: it flattens the bone onto a plane, a line or a point" if smallest < 1e-9 else
            f"scales the bone by {largest:.3g}" if largest > MAX_SCALE else f"shrinks the bone to {smallest:.3g}")
    raise rec.error(lines[b], f"the matrix of bone {b} ({bones[b].label}) {what}; a pose moves each bone rigidly "
                              f"(a rotation and a translation; scales between 1/{MAX_SCALE:g} and {MAX_SCALE:g} are "
                              "read): write the frame again from its pose, keys or clip")


def _refuse_twice_listed(rec, bones: list[BoneSegment], lines: list[int]) -> None:
    """The first bone (in file order) whose joints equal an earlier bone's (``BoneSegment.same_segment``'s
    tolerance), refused at its line. All pairs at once: pair by pair was three quarters of reading a
    1064-frame clip's .trans files (#61 item 11)."""
    if len(bones) < 2:
        return
    ends = np.array([np.r_[b.proximal, b.distal] for b in bones], np.float64)
    earlier, later = ends[:, None, :], ends[None, :, :]
    same = (np.abs(later - earlier) <= 1e-6 + 1e-5 * np.abs(earlier)).all(-1)  # np.allclose, other = earlier
    same &= np.triu(np.ones_like(same), 1)  # [k, j]: bone j after bone k
    if same.any():
        j = int(np.flatnonzero(same.any(0))[0])
        k = int(np.flatnonzero(same[:, j])[0])
        raise rec.error(lines[j], f"bone {bones[j].label} is listed twice (bone {k} has the same joints); "
                                  "each bone has one 'Root:' line")


def _read_rooted(path, *, matrices: bool, points: bool):
    rec = read_records(path)
    records = rec.records
    bones: list[BoneSegment] = []
    mats: list[np.ndarray] = []
    rows: list[tuple[int, list[str]]] = []
    owner: list[int] = []
    root_lines: list[int] = []
    matrix_lines: list[int] = []
    i = 0
    while i < len(records):
        line, toks = records[i]
        if _is_root(toks):
            bones.append(_parse_root(rec, line, toks))
            root_lines.append(line)
            i += 1
            if matrices:
                mats.append(_parse_matrix(rec, records, i, line, points_follow=points))
                matrix_lines.append(records[i][0])
                i += 4
            continue
        if not bones:
            raise rec.error(line, f"expected a {ROOT_SYNTAX} line before any data, got {toks[0]!r}")
        if not points:
            raise rec.error(line, f"expected a {ROOT_SYNTAX} line, got {' '.join(toks)!r}")
        rows.append((line, toks))
        owner.append(len(bones) - 1)
        i += 1
    if not bones:
        raise rec.error(None, f"no {ROOT_SYNTAX} line, expected at least one bone")
    _refuse_twice_listed(rec, bones, root_lines)
    if matrices:
        _refuse_what_no_pose_does(rec, bones, matrix_lines, np.array(mats))
    arr = parse_point_rows(rec, rows, (4, 5), "x y z dt [thinness]")
    _check_point_count(rec, len(rows))
    if len(arr):
        coords = arr[:, :3].astype(np.int64)
        _, first, counts = np.unique(coords, axis=0, return_index=True, return_counts=True)
        if (counts > 1).any():
            dup = np.setdiff1d(np.arange(len(coords)), first)[0]
            twin = np.flatnonzero((coords == coords[dup]).all(axis=1))[0]
            raise rec.error(rows[dup][0], f"point {tuple(coords[dup].tolist())} is listed twice (also on line "
                            f"{rows[twin][0]}); a point belongs to at most one bone")
    return rec, bones, np.array(mats).reshape(-1, 4, 4), arr, np.array(owner, dtype=np.int32)


def read_connect(path: str | Path, *, ownership: bool = True) -> Connectivity:
    """Read a ``.connect`` file (docs/formats.md), with the ownership beside it (``NAME.owners.nrrd``) when
    there is one and ``ownership``."""
    rec, bones, _, arr, owner = _read_rooted(path, matrices=False, points=True)
    threshold = rec.header.get("thinness")
    if threshold is not None:
        threshold = parse_float(rec, None, threshold, "'# thinness:' header")
    conn = Connectivity(bones, arr[:, :3], arr[:, 3], arr[:, 4], owner, parse_metric(rec), threshold,
                        parse_geometry(rec), _parse_joints(rec))
    from volanim_core.io.ownership_files import attach_ownership

    return attach_ownership(conn, path) if ownership else conn


def read_trans(path: str | Path) -> Trans:
    """Read a ``.trans`` file: per bone a ``Root:`` line and 4 matrix rows (and the grid they are on)."""
    rec, bones, mats, _, _ = _read_rooted(path, matrices=True, points=False)
    return Trans(bones, mats, parse_geometry(rec))


def read_tskel(path: str | Path) -> Tskel:
    """Read a ``.tskel`` file: per bone ``Root:``, 4 matrix rows, then points."""
    rec, bones, mats, arr, owner = _read_rooted(path, matrices=True, points=True)
    t = Tskel(bones, mats, arr[:, :3], arr[:, 3], arr[:, 4], owner, parse_metric(rec), parse_geometry(rec),
              joints=_parse_joints(rec))
    named = rec.header.get("ownership")
    if named:
        from volanim_core.io.ownership_files import read_ownership

        own_path = Path(path).parent / named.strip()
        if not own_path.exists():
            raise rec.error(None, f"its '# ownership:' file {own_path} is missing: put it back beside the "
                                  "frame, or delete that line to re-grow the thesis's spheres")
        t.ownership = read_ownership(own_path, t)
    return t


def _parse_joints(rec: TextRecords) -> Joints:
    """The ``# joints:`` header (docs/formats.md#joints): ``rigid`` (also when absent: the seed's files) or
    ``smooth [WIDTH]``."""
    return parse_header(rec, "joints", Joints.from_header, RIGID)


def _joints_header(joints: Joints) -> list[str]:
    """Written only for smooth joints: a rigid file stays byte for byte what it was."""
    return [f"# joints: {joints.text()}"] if joints.smooth else []


def _format_matrix(m: np.ndarray) -> list[str]:
    return [" ".join(fmt_float(v) for v in row) for row in np.asarray(m).reshape(4, 4)]


def _bone_blocks(bones, bone_index, points, dt, thinness, matrices=None) -> list[str]:
    order = np.argsort(bone_index, kind="stable")
    starts = np.searchsorted(bone_index[order], np.arange(len(bones) + 1))
    rows = format_point_rows(points[order], dt[order], thinness[order] if thinness is not None else None)
    lines = []
    for b, root in enumerate(bones):
        lines.append(_format_root(root))
        if matrices is not None:
            lines.extend(_format_matrix(matrices[b]))
        lines.extend(rows[starts[b] : starts[b + 1]])
    return lines


def _geometry_header(geometry) -> list[str]:
    return [] if geometry.is_identity else [f"# geometry: {geometry.header_value()}"]


def write_connect(path: str | Path, conn: Connectivity, *, thinness: float | None = None) -> None:
    """Write a ``.connect`` file atomically.

    When ``thinness`` is given only points with thinness >= it are written and
    it is recorded in the ``# thinness:`` header (docs/formats.md's convention).
    """
    keep = np.ones(len(conn), bool)
    if thinness is not None:
        keep = ~(conn.thinness < thinness)  # NaN thinness (unknown) is kept
    th = thinness if thinness is not None else conn.thinness_threshold
    lines = ["# volanim connect 1", f"# points: {int(keep.sum())}"]
    if th is not None:
        lines.append(f"# thinness: {th:.2f}" if round(th, 2) == th else f"# thinness: {fmt_float(th)}")
    lines.append(f"# metric: {conn.metric}")
    lines += _geometry_header(conn.geometry) + _joints_header(conn.joints)
    lines += _bone_blocks(conn.bones, conn.bone[keep], conn.points[keep], conn.dt[keep], conn.thinness[keep])
    atomic_write_text(path, "\n".join(lines) + "\n")


def write_trans(path: str | Path, trans: Trans) -> None:
    """Write a ``.trans`` file atomically (a ``# geometry:`` line when it is on a grid other than identity)."""
    lines = ["# volanim trans 1", *_geometry_header(trans.geometry)]
    for root, m in zip(trans.bones, trans.matrices):
        lines.append(_format_root(root))
        lines.extend(_format_matrix(m))
    atomic_write_text(path, "\n".join(lines) + "\n")


def write_tskel(path: str | Path, tskel: Tskel) -> None:
    """Write a ``.tskel`` file atomically, points grouped under their bone."""
    lines = ["# volanim tskel 1", f"# points: {len(tskel.points)}", f"# metric: {tskel.metric}",
             *_geometry_header(tskel.geometry), *_joints_header(tskel.joints), *_ownership_header(path, tskel)]
    lines += _bone_blocks(tskel.bones, tskel.bone, tskel.points, tskel.dt, tskel.thinness, tskel.matrices)
    atomic_write_text(path, "\n".join(lines) + "\n")


def _ownership_header(path, tskel: Tskel) -> list[str]:
    """``# ownership: FILE`` (relative to the frame) when the frame's rig has an ownership on disk."""
    own = getattr(tskel, "ownership", None)
    if own is None or own.path is None or tskel.joints.smooth:
        return []
    target, here = Path(own.path).resolve(), Path(path).resolve().parent
    return [f"# ownership: {os.path.relpath(target, here)}"]


def connect_filename(stem: str, thinness: float) -> str:
    """``NAME.THINNESS.connect``, the convention for a file saved at a slider value."""
    return f"{stem}.{thinness:.2f}.connect"
