"""#64: the temporaries of a write whose process is gone are swept by the next write to the same folder,
and a live writer's never are. Pids are reused (a container runs through a few thousand): a temporary
naming a live pid whose process started after the file was last written is a dead writer's."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np

from volanim_core import io
from volanim_core.io.atomic import pending_name

WRITE_AND_WAIT = """
import sys, time
from pathlib import Path
from volanim_core.io.atomic import pending_name
tmp = Path(sys.argv[1]) / pending_name("dest.vti", ".tmp.vti")
tmp.write_bytes(b"x" * 4096)
print(tmp, flush=True)
time.sleep(600)
"""


def _writer(folder):
    proc = subprocess.Popen([sys.executable, "-c", WRITE_AND_WAIT, str(folder)], stdout=subprocess.PIPE, text=True)
    line = proc.stdout.readline().strip()
    proc.stdout.close()
    return proc, line


def test_a_killed_writers_temporary_is_swept_by_the_next_write(tmp_path):
    proc, tmp = _writer(tmp_path)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert os.path.exists(tmp)
    io.write_volume(tmp_path / "dest.vti", np.zeros((3, 3, 3), np.uint8))
    assert not os.path.exists(tmp)


def test_a_live_writers_temporary_stays_and_a_reused_pids_goes(tmp_path):
    proc, live = _writer(tmp_path)
    try:
        # a file naming the live process's pid but last written before that process began: a dead
        # writer's whose pid was handed on
        reused = tmp_path / f".other.vti.{proc.pid}-0123abcd.tmp.vti"
        reused.write_bytes(b"y")
        past = time.time() - 3600
        os.utime(reused, (past, past))
        io.write_volume(tmp_path / "dest.vti", np.zeros((3, 3, 3), np.uint8))
        assert os.path.exists(live) and not reused.exists()
        assert not (tmp_path / pending_name("dest.vti")).exists()
    finally:
        proc.kill()
        proc.wait()
