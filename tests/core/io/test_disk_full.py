"""A full disk: every writer raises, leaves the file that was there byte for byte and leaves no litter (#38).

The writers run in a tmpfs of 2 MB mounted in a mount namespace of their own (``unshare``: no root
needed, nothing to unmount if the test dies), whose disk is filled to 24 kB before each write.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

DRIVER = Path(__file__).with_name("disk_full_writers.py")


@pytest.mark.slow
def test_every_writer_on_a_full_disk_raises_and_keeps_the_old_file(tmp_path):
    full, spare = tmp_path / "full", tmp_path / "spare"
    full.mkdir()
    spare.mkdir()
    assert shutil.which("unshare"), "util-linux's unshare makes the small disk"
    script = f'mount -t tmpfs -o size=2m tmpfs "{full}" && exec "{sys.executable}" "{DRIVER}" "{full}" "{spare}"'
    out = subprocess.run(["unshare", "--user", "--map-root-user", "--mount", "sh", "-c", script],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    rows = [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]
    assert rows and rows[-1]["writer"] == "sequence .zarr", out.stderr[-2000:]
    seq = rows.pop()
    frames = rows.pop()
    print(f"\nframe folder: {frames}")
    print(f"\nsequence .zarr: {seq}")
    table = "\n".join(f"{r['writer']:<24} raised: {bool(r['raised'])!s:<6} old intact: {r['old_intact']!s:<6} "
                      f"litter: {r['litter']}" for r in rows)
    print("\n" + table)
    assert len(rows) == 23, out.stderr[-2000:]
    for r in rows:
        assert r["raised"] and not r.get("traceback"), r
        assert r["old_intact"], r
        assert r["litter"] == [], r
    unnamed = [(r["writer"], r["raised"]) for r in rows if r["target"] not in r["raised"]]
    assert not unnamed, unnamed  # the message names the file that did not fit (#64)
    # and how much room it needs and how much is free (#89: "it needs more" said neither)
    vague = [(r["writer"], r["raised"]) for r in rows if not re.search(r"needs? [^,;]*\d[\d,]* bytes", r["raised"])
             or not re.search(r"[\d,]+ bytes (are )?free", r["raised"])]
    assert not vague, vague
    # a clip's frames: the run stops naming a frame, the folder is marked and refused, the rerun completes it
    assert frames["writer"] == "frame folder .trans" and ".trans" in (frames["raised"] or ""), frames
    assert 0 < frames["written"] < frames["frames"] and frames["marked"], frames
    assert "walk.incomplete" in (frames["read_refused"] or ""), frames
    assert not frames["marked_after_rerun"] and frames["rerun_equal"], frames
    # a store is resumable: it stops with the error, what it recorded verifies, the rerun finishes it
    assert seq["raised"] and "s.zarr" in seq["raised"] and 0 <= seq["recorded"] < seq["frames"], seq
    assert seq["recorded_verify"] and seq["skipped_on_resume"] == seq["recorded"], seq
    assert seq["resumed_equal"], seq
    # #87: the room it needs, from the frames it wrote (a walk's frame compresses ~10^4 x below its grid's bytes:
    # "up to 433 MB" was said for a store that needed 0.5 MB more)
    said = re.search(r"about ([\d.]+) (bytes|KB|MB|GB) more \((\d+) frames", seq["raised"])
    assert said and int(said[3]) == seq["frames"] - seq["recorded"], seq
    more = float(said[1]) * 1024 ** ["bytes", "KB", "MB", "GB"].index(said[2])
    needed = seq["store_bytes"] * (seq["frames"] - seq["recorded"]) / seq["frames"]
    assert 0.7 < more / needed < 1.4, (more, needed)
