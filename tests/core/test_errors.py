"""FormatError crosses process boundaries whole: a frame read in a worker process (render, sequence on a
cluster) raises it, and the driver shows the message. Unpickling called __init__ with the message alone, so
the driver reported "a worker process died" instead (#89)."""

import pickle
from concurrent.futures import ProcessPoolExecutor

import pytest

from volanim_core.errors import FormatError


def _refuse(path):
    raise FormatError(path, "frame 3: its shard cannot be decoded", 7)


def test_a_format_error_pickles_with_its_file_line_and_reason():
    err = pickle.loads(pickle.dumps(FormatError("a/b.zarr", "frame 3 is damaged", 7)))
    assert (err.path, err.line, err.reason, str(err)) == ("a/b.zarr", 7, "frame 3 is damaged",
                                                          "a/b.zarr:7: frame 3 is damaged")


def test_a_format_error_raised_in_a_worker_process_reaches_the_caller():
    with ProcessPoolExecutor(1) as pool, pytest.raises(FormatError, match=r"^s\.zarr:7: frame 3: its shard"):
        pool.submit(_refuse, "s.zarr").result()
