"""kill -9 of a real studio process during random edits: the recovered session is the last autosave,
the pose included (issue #37: a pose dragged before a kill was missing from the recovered session)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from volanim_studio.model import autosave

from ..conftest import JOB_TIMEOUT_MS, new_window
from .studio_under_edits import session_state

DRIVER = Path(__file__).with_name("studio_under_edits.py")


def _log(path: Path) -> list[dict]:
    lines = path.read_text().splitlines() if path.exists() else []
    out = []
    for line in lines:
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:  # the last line, cut by the kill
            pass
    return out


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2])
def test_a_killed_studio_recovers_its_last_autosave(qtbot, tmp_path, recovery_dir, seed):
    log = tmp_path / "edits.jsonl"
    env = {**os.environ, "VOLANIM_RECOVERY_DIR": str(recovery_dir),
           "PYTHONPATH": os.pathsep.join([str(Path(__file__).parents[2]), os.environ.get("PYTHONPATH", "")])}
    errors = tmp_path / "stderr.txt"
    with open(errors, "wb") as err:
        proc = subprocess.Popen([sys.executable, str(DRIVER), str(log), str(seed)], env=env,
                                stdout=subprocess.DEVNULL, stderr=err)
    try:
        deadline = time.monotonic() + JOB_TIMEOUT_MS / 1000
        saves = 4 + seed  # let it autosave a few times, then kill it wherever it is
        while sum("saved" in e for e in _log(log)) < saves:
            assert proc.poll() is None, f"the studio died by itself: {errors.read_text()[-2000:]}"
            assert time.monotonic() < deadline, "the studio made no autosaves"
            time.sleep(0.05)
        time.sleep(0.05 * seed)
        proc.send_signal(signal.SIGKILL)
        proc.wait(30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(30)
    entries = _log(log)
    saving = [e for e in entries if "saving" in e]
    finished = entries[-1].get("saved") == saving[-1]["saving"]
    # a kill inside the last save leaves that save or the one before it (a save is one unit)
    expected = [saving[-1]["state"]] if finished else [saving[-1]["state"], saving[-2]["state"]]
    assert any(s["pose"]["angles"] for s in expected), "the edits posed nothing: the test proves little"

    found = autosave.find_recoveries(recovery_dir)
    assert len(found) == 1
    w = new_window(qtbot)
    try:
        restored = []
        worker = w.session.offer_recovery(ask=lambda path: restored.append(path) or True)
        assert restored == found and worker is not None
        qtbot.waitUntil(lambda: len(w.doc.bones) == 18 and not w.busy, timeout=JOB_TIMEOUT_MS)
        qtbot.waitUntil(lambda: "Restored" in w.statusBar().currentMessage(), timeout=JOB_TIMEOUT_MS)
        assert session_state(w) in expected
        assert w.isWindowModified()  # saved nowhere yet
    finally:
        w.doc.undo.mark_clean()
        w.close()
        assert not w.busy
