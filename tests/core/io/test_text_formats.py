"""Round trips and malformed input for the text formats of docs/formats.md."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io
from volanim_core.errors import FormatError
from volanim_core.rig.connectivity import Trans, Tskel
from volanim_core.skeleton.points import Skeleton


# spec: docs/formats.md#skel
def test_skel_round_trip(tmp_path, small_skeleton):
    path = tmp_path / "a.skel"
    io.write_skel(path, small_skeleton)
    back = io.read_skel(path)
    assert np.array_equal(back.points, small_skeleton.points)
    assert np.array_equal(back.dt, small_skeleton.dt)  # shortest repr is exact
    assert np.isnan(back.thinness).all()


# spec: docs/formats.md#mskel
def test_mskel_round_trip_and_sorted(tmp_path, small_skeleton):
    shuffled = Skeleton(small_skeleton.points[::-1], small_skeleton.dt[::-1], small_skeleton.thinness[::-1])
    path = tmp_path / "a.mskel"
    io.write_mskel(path, shuffled)
    lines = [ln for ln in path.read_text().splitlines() if not ln.startswith("#")]
    thin = [float(ln.split()[4]) for ln in lines]
    assert thin == sorted(thin, reverse=True)
    assert io.read_mskel(path) == small_skeleton


# spec: docs/formats.md#mskel
def test_mskel_345_metric_round_trip(tmp_path):
    s = Skeleton([[1, 2, 3], [4, 5, 6]], [6.0, 3.0], [2.0, 1.0], metric="345")
    io.write_mskel(tmp_path / "c.mskel", s)
    assert io.read_mskel(tmp_path / "c.mskel") == s


# spec: docs/formats.md#conventions
def test_reader_tolerates_comments_tabs_crlf_blank_lines(tmp_path):
    path = tmp_path / "t.mskel"
    path.write_bytes(b"# volanim mskel 1\r\n\r\n1\t2 3 1.5 0.7  # trailing comment\r\n\t\n4 5 6 1 0.2\r\n")
    s = io.read_mskel(path)
    assert s.points.tolist() == [[1, 2, 3], [4, 5, 6]]
    assert s.thinness.tolist() == [0.7, 0.2]


# spec: docs/formats.md#mskel
def test_mskel_reader_does_not_rely_on_order(tmp_path):
    path = tmp_path / "u.mskel"
    path.write_text("1 1 1 1 0.1\n2 2 2 2 0.9\n3 3 3 3 0.5\n")
    assert io.read_mskel(path).thinness.tolist() == [0.9, 0.5, 0.1]


# spec: docs/formats.md#bones
def test_bones_round_trip(tmp_path, small_bones):
    io.write_bones(tmp_path / "b.bones", small_bones)
    assert io.read_bones(tmp_path / "b.bones") == small_bones
    text = (tmp_path / "b.bones").read_text()
    assert "joint L_ANKLE 216.5 160 702" in text and "bone L_HIP L_KNEE L_THIGH" in text


# spec: docs/formats.md#bones
def test_bones_formats_md_example_parses(tmp_path):
    (tmp_path / "x.bones").write_text(
        "# volanim bones 1\njoint L_HIP 212 140 401\njoint L_KNEE 214 152 561\n"
        "joint L_ANKLE 216 160 702\nbone L_HIP L_KNEE\nbone L_KNEE L_ANKLE\n"
    )
    b = io.read_bones(tmp_path / "x.bones")
    assert [x.proximal for x in b.bones] == ["L_HIP", "L_KNEE"]
    assert b.parent(1) == 0 and b.parent(0) is None


# spec: docs/formats.md#connections
def test_connections_round_trip(tmp_path, small_bones):
    io.write_connections(tmp_path / "b.connections", small_bones)
    assert io.read_connections(tmp_path / "b.connections") == [("L_HIP", "L_KNEE"), ("L_KNEE", "L_ANKLE")]


# spec: docs/formats.md#connect
def test_connect_round_trip(tmp_path, small_connect):
    io.write_connect(tmp_path / "a.connect", small_connect)
    assert io.read_connect(tmp_path / "a.connect") == small_connect


# spec: docs/formats.md#connect
def test_connect_formats_md_example(tmp_path):
    (tmp_path / "m.1.40.connect").write_text(
        "# volanim connect 1\n# thinness: 1.40\n# metric: euclid\n"
        "Root: 212 140 401 :: 214 152 561 L_THIGH\n201 139 420 9.2 1.81\n"
        "Root: 214 152 561 :: 216 160 702 L_SHIN\n"
    )
    c = io.read_connect(tmp_path / "m.1.40.connect")
    assert c.thinness_threshold == 1.4
    assert [b.name for b in c.bones] == ["L_THIGH", "L_SHIN"]
    assert c.bone.tolist() == [0] and c.dt.tolist() == [9.2]


# spec: docs/formats.md#connect
def test_connect_written_at_thinness_keeps_only_points_at_or_above(tmp_path, small_connect):
    t = 0.5
    io.write_connect(tmp_path / "a.connect", small_connect, thinness=t)
    back = io.read_connect(tmp_path / "a.connect")
    assert (back.thinness >= t).all()
    assert len(back) == int((small_connect.thinness >= t).sum())
    assert back.thinness_threshold == t


# spec: docs/formats.md#connect
def test_connect_filename_convention():
    assert io.connect_filename("man", 1.4) == "man.1.40.connect"


# spec: docs/formats.md#connect
def test_connect_empty_bone_is_root_line_alone(tmp_path, small_connect):
    only_first = small_connect.bone == 0
    from volanim_core.rig.connectivity import Connectivity

    c = Connectivity(small_connect.bones, small_connect.points[only_first], small_connect.dt[only_first],
                     small_connect.thinness[only_first], small_connect.bone[only_first])
    io.write_connect(tmp_path / "e.connect", c)
    assert (tmp_path / "e.connect").read_text().rstrip().splitlines()[-1].startswith("Root:")
    assert io.read_connect(tmp_path / "e.connect") == c


def _trans(small_connect, rng):
    mats = np.tile(np.eye(4), (len(small_connect.bones), 1, 1))
    mats[:, 3, :3] = rng.normal(size=(len(mats), 3))
    mats[0, :3, :3] = [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]
    return mats


# spec: docs/formats.md#trans
def test_trans_round_trip(tmp_path, small_connect, rng):
    t = Trans(small_connect.bones, _trans(small_connect, rng))
    io.write_trans(tmp_path / "a.trans", t)
    assert io.read_trans(tmp_path / "a.trans") == t


# spec: docs/formats.md#tskel
def test_tskel_round_trip(tmp_path, small_connect, rng):
    c = small_connect
    t = Tskel(c.bones, _trans(c, rng), c.points, c.dt, c.thinness, c.bone, metric="345")
    io.write_tskel(tmp_path / "a.tskel", t)
    assert io.read_tskel(tmp_path / "a.tskel") == t


# spec: docs/formats.md#tskel
def test_tskel_three_row_matrix_before_a_point_with_dt_1_is_refused_by_the_count(tmp_path):
    # "x y z 1" is a valid translation row: without the count this file reads as
    # one bone translated by (10, 10, 10) holding one point, silently.
    body = "Root: 0 0 0 :: 0 0 10\n1 0 0 0\n0 1 0 0\n0 0 1 0\n10 10 10 1\n11 10 10 2\n"
    (tmp_path / "seed.tskel").write_text(body)
    # the seed's files have no count: all whole numbers cannot say which it is, so the line is named (#89:
    # it was read as a translation, and the point was silently gone)
    with pytest.raises(io.FormatError, match=r"seed.tskel:5: '10 10 10 1' may be this matrix's translation.*"
                                             r"add a '# points: N' line"):
        io.read_tskel(tmp_path / "seed.tskel")
    # rows 1-3 written with decimals and row 4 not: row 4 is a point line
    (tmp_path / "dec.tskel").write_text(body.replace("1 0 0 0\n0 1 0 0\n0 0 1 0",
                                                     "1.0 0.0 0.0 0.0\n0.0 1.0 0.0 0.0\n0.0 0.0 1.0 0.0"))
    with pytest.raises(io.FormatError, match=r"dec.tskel:5: the matrix has 3 rows: '10 10 10 1' is written as a point"):
        io.read_tskel(tmp_path / "dec.tskel")
    # what cannot be a point is read as the seed's files always were: a translation with a fraction, or none
    for row, points in (("10 10 10.5 1", 1), ("0 0 0 1", 1)):
        (tmp_path / "t.tskel").write_text(body.replace("10 10 10 1", row))
        assert len(io.read_tskel(tmp_path / "t.tskel")) == points
    (tmp_path / "m.tskel").write_text("# volanim tskel 1\n# points: 2\n" + body)
    with pytest.raises(io.FormatError, match=r"m.tskel:2: the header says 2 points but the file has 1"):
        io.read_tskel(tmp_path / "m.tskel")


# spec: docs/formats.md#connect
@pytest.mark.parametrize("count", ["3", "x", "-1", "9" * 13, "²"])
def test_point_count_header_must_match(tmp_path, count):
    (tmp_path / "a.connect").write_text(f"# points: {count}\nRoot: 0 0 0 :: 0 0 10\n1 1 1 2\n")
    with pytest.raises(io.FormatError, match="a.connect:1: .*points"):
        io.read_connect(tmp_path / "a.connect")


# spec: docs/formats.md#tskel
def test_volanim_writes_the_point_count(tmp_path, small_connect, rng):
    c = small_connect
    io.write_connect(tmp_path / "a.connect", c, thinness=0.5)
    assert f"# points: {int((c.thinness >= 0.5).sum())}\n" in (tmp_path / "a.connect").read_text()
    io.write_tskel(tmp_path / "a.tskel", Tskel(c.bones, _trans(c, rng), c.points, c.dt, c.thinness, c.bone))
    assert f"# points: {len(c)}\n" in (tmp_path / "a.tskel").read_text()


# spec: docs/formats.md#tskel
def test_tskel_with_zero_points(tmp_path, small_connect):
    t = Tskel(small_connect.bones, np.tile(np.eye(4), (2, 1, 1)), np.zeros((0, 3)), [], None, [])
    io.write_tskel(tmp_path / "z.tskel", t)
    assert len(io.read_tskel(tmp_path / "z.tskel")) == 0


IDENTITY = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
GOOD_TSKEL_HEAD = "Root: 0 0 0 :: 1 1 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"


# spec: docs/formats.md#conventions
@pytest.mark.parametrize(
    ("reader", "text", "line", "words"),
    [
        (io.read_mskel, "1 2 3 1.5\n", 1, "expected 5 columns"),
        (io.read_mskel, "1 2 3 1.5 0.1\n1 2 3 1.5 0.1 7\n", 2, "expected 5 columns"),
        (io.read_mskel, "1 2 3 1.5 0.1\n1 2 x 1.5 0.1\n", 2, "integer coordinate z"),
        (io.read_mskel, "1 2 3 abc 0.1\n", 1, "number for dt"),
        (io.read_mskel, "1 2 3.5 1 0.1\n", 1, "integer coordinate z"),
        (io.read_mskel, "1 2 3 -1 0.1\n", 1, "dt >= 0"),
        (io.read_mskel, "1 2 3 nan 0.1\n", 1, "finite"),
        (io.read_skel, "1 2 3 1.5 0.1\n", 1, "expected 4 columns"),
        (io.read_bones, "joint A 1 2\n", 1, "joint NAME x y z"),
        (io.read_bones, "joint A 1 2 3\njoint A 1 2 3\n", 2, "defined twice"),
        (io.read_bones, "joint A 1 2 3\nbone A B\n", 2, "which no 'joint' line defines"),
        (io.read_bones, "joint A 1 2 3\nlimb A A\n", 2, "'joint' or 'bone'"),
        (io.read_bones, "joint A 1 two 3\n", 1, "number for joint A y"),
        (io.read_connections, "A B C\n", 1, "two joint names"),
        (io.read_connect, "Root: 1 2 3 4 5 6\n", 1, "no '::'"),
        (io.read_connect, "Root: 1 2 :: 4 5 6\n", 1, "expected 'Root: x y z :: x y z"),
        (io.read_connect, "1 2 3 4\n", 1, "before any data"),
        (io.read_connect, "Root: 0 0 0 :: 1 1 1\n1 2 3\n", 2, "expected 4 or 5 columns"),
        (io.read_connect, "Root: 0 0 0 :: 1 1 1\n1 2 3 1\nRoot: 1 1 1 :: 2 2 2\n1 2 3 1\n", 4, "listed twice"),
        (io.read_connect, "# metric: 456\nRoot: 0 0 0 :: 1 1 1\n", None, "unknown '# metric"),
        # the second of two bones with the same joints, named at its own line (checked all pairs at once)
        (io.read_connect, "Root: 0 0 0 :: 1 1 1\n1 2 3 1\nRoot: 5 5 5 :: 6 6 6\nRoot: 0 0 0 :: 1 1 1.0000001\n"
         "4 4 4 1\n", 4, "bone (0 0 0)-(1 1 1) is listed twice (bone 0 has the same joints)"),
        (io.read_trans, ("Root: 0 0 0 :: 1 1 1\n" + IDENTITY + "Root: 0 0 0 :: 1 1 2\n" + IDENTITY
                         + "Root: 0 0 0 :: 1 1 2\n" + IDENTITY), 11,
         "bone (0 0 0)-(1 1 2) is listed twice (bone 1 has the same joints)"),
        (io.read_trans, "Root: 0 0 0 :: 1 1 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n", 1, "has 3 rows"),
        (io.read_trans, "Root: 0 0 0 :: 1 1 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\nRoot: 1 1 1 :: 2 2 2\n", 5, "has 3 rows"),
        (io.read_trans, "Root: 0 0 0 :: 1 1 1\n1 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n", 2, "matrix row 1 of 4"),
        (io.read_trans, GOOD_TSKEL_HEAD + "1 2 3 4\n", 6, "expected a 'Root:"),
        (io.read_tskel, "Root: 0 0 0 :: 1 1 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n5 5 5 2\n", 2, "not affine"),
        (io.read_tskel, GOOD_TSKEL_HEAD + "1 2 3\n", 6, "expected 4 or 5 columns"),
    ],
)
def test_malformed_text_gives_one_error_type_naming_file_and_line(tmp_path, reader, text, line, words):
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(FormatError) as err:
        reader(path)
    assert err.value.line == line
    assert words in str(err.value)
    assert str(path) in str(err.value)
    if line is not None:
        assert f"{path}:{line}:" in str(err.value)


# spec: docs/formats.md#conventions
@pytest.mark.parametrize("reader", [io.read_skel, io.read_mskel, io.read_bones, io.read_connections,
                                    io.read_connect, io.read_trans, io.read_tskel])
@pytest.mark.parametrize("content", [b"", b"# only a comment\n\n", b"\x00\x01\x02\xff\xfe binary", b"\xff\xfe\xfd"])
def test_empty_and_binary_files(tmp_path, reader, content):
    path = tmp_path / "f"
    path.write_bytes(content)
    with pytest.raises(FormatError, match=str(path)):
        reader(path)


# spec: docs/formats.md#conventions
def test_truncated_file_is_an_error(tmp_path, small_connect):
    path = tmp_path / "a.mskel"
    io.write_mskel(path, Skeleton(small_connect.points, small_connect.dt, small_connect.thinness))
    data = path.read_bytes()
    path.write_bytes(data[: data.rindex(b" ")])  # the last line loses its thinness column
    with pytest.raises(FormatError, match=r"a\.mskel:\d+: expected 5 columns"):
        io.read_mskel(path)


# spec: docs/formats.md#conventions
def test_missing_file(tmp_path):
    with pytest.raises(FormatError, match="cannot read file"):
        io.read_bones(tmp_path / "nope.bones")


# spec: docs/formats.md#conventions
def test_writer_is_atomic_keeps_old_file_on_failure(tmp_path, small_bones, monkeypatch):
    path = tmp_path / "b.bones"
    io.write_bones(path, small_bones)
    before = path.read_bytes()

    class Boom(Exception):
        pass

    def explode(*a, **k):
        raise Boom

    import volanim_core.io.atomic as atomic

    monkeypatch.setattr(atomic.os, "fsync", explode)  # fail after writing, before rename
    with pytest.raises(Boom):
        io.write_bones(path, small_bones)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["b.bones"]  # no temporary left behind


# spec: docs/formats.md#conventions
def test_written_files_get_normal_permissions(tmp_path, small_bones):
    import os

    io.write_bones(tmp_path / "a.bones", small_bones)
    mask = os.umask(0)
    os.umask(mask)
    assert (tmp_path / "a.bones").stat().st_mode & 0o777 == 0o666 & ~mask
    os.chmod(tmp_path / "a.bones", 0o640)
    io.write_bones(tmp_path / "a.bones", small_bones)  # replacing keeps the old mode
    assert (tmp_path / "a.bones").stat().st_mode & 0o777 == 0o640


def _killed_writer(tmp_path, write) -> int:
    """Fork a child that writes in a loop and SIGKILL it mid-write; returns its (dead) pid."""
    import os
    import signal
    import time

    pid = os.fork()
    if pid == 0:
        try:
            while True:
                write()
        finally:
            os._exit(0)
    time.sleep(0.3)
    os.kill(pid, signal.SIGKILL)
    os.waitpid(pid, 0)
    return pid


# spec: docs/formats.md#conventions
def test_temporaries_of_killed_writers_are_cleaned_on_the_next_write(tmp_path, small_bones):
    """A kill -9 mid-write leaves a hidden temporary; the next write to the same folder removes it."""
    import os
    import time

    path = tmp_path / "b.bones"
    dead = _killed_writer(tmp_path, lambda: io.write_bones(path, small_bones))
    # what a kill leaves (made by hand too, in case the kill landed between writes)
    (tmp_path / f".b.bones.{dead}-0123abcd.tmp").write_text("half")
    legacy = tmp_path / ".b.bones.k3j_x9a2.tmp"  # an older version's mkstemp name
    legacy.write_text("half")
    old = time.time() - 3600
    os.utime(legacy, (old, old))
    alive = tmp_path / f".other.bones.{os.getpid()}-0123abcd.tmp"  # a write in progress (this process)
    alive.write_text("being written")
    user = tmp_path / ".notes.tmp"  # not ours: never touched
    user.write_text("mine")
    io.write_bones(path, small_bones)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([".notes.tmp", alive.name, "b.bones"])
    assert io.read_bones(path) == small_bones


# spec: docs/formats.md#conventions
def test_vtk_temporaries_of_killed_writers_are_cleaned(tmp_path):
    import numpy as np

    path = tmp_path / "v.vti"
    vol = np.zeros((4, 5, 6), np.uint8)
    dead = _killed_writer(tmp_path, lambda: io.write_volume(path, vol))
    (tmp_path / f".v.{dead}-0123abcd.tmp.vti").write_bytes(b"half")
    io.write_volume(path, vol)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.vti"]
