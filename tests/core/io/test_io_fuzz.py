"""Fuzz: readers raise FormatError for anything they cannot read, never another type."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from volanim_core import io
from volanim_core.errors import FormatError

READERS = [io.read_skel, io.read_mskel, io.read_bones, io.read_connections, io.read_connect,
           io.read_trans, io.read_tskel]

# Text built from the formats' own vocabulary, so the fuzzer reaches deep into the parsers.
WORDS = st.sampled_from(["Root:", "::", "joint", "bone", "#", "# metric: 345", "# thinness: x", "nan", "inf",
                         "-1", "0", "1", "2.5", "1e400", "A", "B", "\t", "\r", "1 2 3 4", "1 2 3 4 5",
                         "0 0 0 1", "Root: 1 2 3 :: 4 5 6 N", "joint A 1 2 3", "bone A B"])
LINES = st.lists(st.lists(WORDS, max_size=8).map(" ".join), max_size=12).map("\n".join)


@pytest.mark.parametrize("reader", READERS, ids=lambda r: r.__name__)
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=LINES)
def test_text_readers_only_raise_format_error(tmp_path, reader, text):
    path = tmp_path / "fuzz.txt"
    path.write_text(text)
    try:
        reader(path)
    except FormatError as exc:
        assert str(path) in str(exc)


@pytest.mark.parametrize("reader", READERS, ids=lambda r: r.__name__)
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.binary(max_size=300))
def test_text_readers_on_random_bytes(tmp_path, reader, data):
    path = tmp_path / "fuzz.bin"
    path.write_bytes(data)
    try:
        reader(path)
    except FormatError:
        pass


@pytest.mark.parametrize("name", ["f.VOL", "f.2x2x2.vol", "f.nrrd"])
@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.one_of(st.binary(max_size=300), st.just(b"NRRD0004\ntype: uchar\nsizes: 2 2 2\n\n" + b"\0" * 8),
                      st.binary(max_size=40).map(lambda b: b"NRRD0004\n" + b)))
def test_volume_readers_only_raise_format_error(tmp_path, name, data):
    path = tmp_path / name
    path.write_bytes(data)
    try:
        io.read_volume(path)
    except FormatError:
        pass
