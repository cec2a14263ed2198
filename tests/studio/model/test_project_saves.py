"""A project save and an autosave are one unit: kill -9 at any moment leaves a consistent last state.

The writer runs in a forked child that saves generation after generation; the
parent kills it at a random moment (SIGKILL: no cleanup of any kind) and then
reads what is on disk. Each generation moves the first joint to x = g and
attaches g + 1 points, so a mix of two generations is detected by comparing
the files with each other.
"""

from __future__ import annotations

import json
import os
import random
import signal
import time

import numpy as np
import pytest

from volanim_core import io, samples
from volanim_core.errors import FormatError
from volanim_core.io import bundle
from volanim_core.rig.bones import BoneSkeleton
from volanim_studio.model import Document, autosave
from volanim_studio.model.project import apply_project, read_project

FIRST_JOINT = next(iter(samples.mannequin_bones().joints))


def make_generation(doc: Document, g: int) -> None:
    base = samples.mannequin_bones()
    joints = dict(base.joints)
    joints[FIRST_JOINT] = np.array([float(g), *joints[FIRST_JOINT][1:]])
    doc.bone_edits.set_bones(BoneSkeleton(joints, base.bones))
    doc.attachments.bone[:] = -1
    doc.attachments.assign(np.arange(g % 200 + 1), 0)


def generation_on_disk(path) -> int:
    """The generation the project at ``path`` holds, checking its files agree with each other."""
    data = read_project(path)
    assert not data["warnings"], data["warnings"]  # the current generation was complete
    g = int(io.read_bones(data["bones"]).joints[FIRST_JOINT][0])
    conn = io.read_connect(data["connect"])
    assert len(conn) == g % 200 + 1, "the .connect is from another save than the .bones"
    fresh = Document()
    fresh.set_skeleton(io.read_mskel(data["mskel"]))
    # applies cleanly: the .connect's bones are the .bones file's (else it raises), no point added
    assert apply_project(fresh, data, path) == []
    assert int((fresh.attachments.bone >= 0).sum()) == g % 200 + 1
    return g


def _kill_while_saving(save, trials: int) -> list[int]:
    """Fork a child that calls ``save(g)`` for g = 1, 2, ...; SIGKILL it after a random delay."""
    seen = []
    rng = random.Random(7)
    for _ in range(trials):
        pid = os.fork()
        if pid == 0:  # the child: save forever until killed
            try:
                g = 1 + seen[-1] if seen else 1
                while True:
                    save(g)
                    g += 1
            finally:
                os._exit(0)
        time.sleep(rng.uniform(0.0, 0.25))
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        on_disk = save.check()
        assert on_disk >= (seen[-1] if seen else 0), "a kill took the project back further than one save"
        seen.append(on_disk)
    return seen


class Saver:
    def __init__(self, doc, path):
        self.doc, self.path = doc, path

    def __call__(self, g):
        make_generation(self.doc, g)
        self.doc.write_project(self.path)

    def check(self) -> int:
        return generation_on_disk(self.path)


# spec: docs/formats.md#project
@pytest.mark.long("kill -9 during a project save: the old or the new project opens, never neither")
@pytest.mark.parametrize("trials", [40])
def test_project_save_survives_kill_9_at_any_moment(tmp_path, doc, trials):
    path = tmp_path / "session.volanim"
    make_generation(doc, 0)
    doc.save_project(path)
    seen = _kill_while_saving(Saver(doc, path), trials)
    assert seen[-1] > 0, "the child never completed a save: the kill moments missed the writes"
    # the next save cleans what the kills left: no temporaries, only the files two manifests name
    doc.save_project(path)
    store = bundle.store_folder(path)
    left = sorted(p.name for p in (*tmp_path.iterdir(), *store.iterdir()) if ".tmp" in p.name)
    assert left == []
    named = {json.loads(path.read_text())[k].split("/")[1] for k in ("bones", "connect", "mskel")}
    named |= {json.loads((store / bundle.PREVIOUS).read_text())[k].split("/")[1]
              for k in ("bones", "connect", "mskel")}
    assert {p.name for p in store.iterdir() if p.name != bundle.PREVIOUS} == named


def test_autosave_survives_kill_9_and_is_offered(tmp_path, doc):
    saver = autosave.Autosaver(doc, tmp_path / "recovery")
    make_generation(doc, 0)
    saver.save()

    class AutoSaver(Saver):
        def __call__(self, g):
            make_generation(self.doc, g)
            saver.save()

    seen = _kill_while_saving(AutoSaver(doc, saver.path), 25)
    assert seen[-1] > 0
    # a folder owned by a dead pid is what the next start finds
    (saver.folder / "session.json").write_text(json.dumps({"pid": 2**22 + 12345}))
    found = autosave.find_recoveries(tmp_path / "recovery")
    assert found == [saver.path]
    assert generation_on_disk(found[0]) == seen[-1]


def test_the_recovery_question_names_the_time_and_what_the_session_holds(tmp_path, doc):
    """It read "Restore the session autosaved at 8698-1795481871958?" (a process id and milliseconds)."""
    import re

    saver = autosave.Autosaver(doc, tmp_path / "recovery")
    make_generation(doc, 7)
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0, -30, 0))
    saver.save()
    text = autosave.describe(saver.path)
    assert re.fullmatch(r"\w{3} \d{2} \w{3} \d{4} \d{2}:\d{2}: 18 bones, 8 attachments, a pose", text), text
    assert str(os.getpid()) not in text


# spec: docs/formats.md#project
def test_a_damaged_save_opens_the_previous_one_and_deletes_nothing(tmp_path, doc):
    path = tmp_path / "p.volanim"
    make_generation(doc, 3)
    doc.save_project(path)
    make_generation(doc, 4)
    doc.save_project(path)
    data = read_project(path)
    with open(data["connect"], "a") as fh:
        fh.write("garbage\n")  # disk trouble, or an edit by hand
    before = sorted(p.name for p in bundle.store_folder(path).iterdir())
    again = read_project(path)
    assert again["warnings"] and "was changed or damaged" in again["warnings"][0]
    assert "opened the previous save" in again["warnings"][0]
    assert int(io.read_bones(again["bones"]).joints[FIRST_JOINT][0]) == 3
    assert sorted(p.name for p in bundle.store_folder(path).iterdir()) == before
    # both generations damaged: a clear error naming the project and the file, still nothing deleted
    with open(again["bones"], "a") as fh:
        fh.write("x")
    with pytest.raises(FormatError, match=r"p\.volanim: its connect file .* changed or damaged"):
        read_project(path)
    assert sorted(p.name for p in bundle.store_folder(path).iterdir()) == before


def test_an_unchanged_skeleton_is_stored_once(tmp_path, doc):
    path = tmp_path / "p.volanim"
    make_generation(doc, 1)
    doc.save_project(path)
    mskel = read_project(path)["mskel"]
    stamp = os.stat(mskel).st_mtime_ns
    make_generation(doc, 2)
    doc.save_project(path)
    assert read_project(path)["mskel"] == mskel and os.stat(mskel).st_mtime_ns == stamp


def test_a_pose_change_saves_without_writing_the_connect_again_and_an_attachment_change_does(tmp_path, doc,
                                                                                             monkeypatch):
    """#65: each autosave formatted and wrote the whole .connect again (the frog's: 1 s on the GUI thread at a
    drag's release) though only the pose had changed. The file is written again exactly when what it holds
    changed: a point's bone, a bone, the joints."""
    written = []
    real = io.write_connect
    monkeypatch.setattr(io, "write_connect", lambda p, conn, **kw: written.append(p) or real(p, conn, **kw))
    path = tmp_path / "p.volanim"
    make_generation(doc, 3)
    doc.save_project(path)
    first = read_project(path)["connect"]
    doc.pose.set_angles(0, (0, -30, 0))
    doc.save_project(path)
    assert read_project(path)["connect"] == first and len(written) == 1  # not formatted again
    doc.attachments.bone[7] = 1  # even an edit behind the undo stack's back
    doc.save_project(path)
    moved = read_project(path)["connect"]
    assert moved != first and io.read_connect(moved).bone.tolist() == doc.attachments.to_connectivity().bone.tolist()
    doc.settings.joints = "smooth"
    doc.save_project(path)
    smooth = read_project(path)["connect"]
    assert smooth != moved and io.read_connect(smooth).joints.kind == "smooth"


def test_project_from_a_newer_version_is_refused(tmp_path):
    path = tmp_path / "new.volanim"
    path.write_text('{"format": "volanim project", "version": 99}')
    with pytest.raises(FormatError, match="newer volanim"):
        read_project(path)


def test_declined_recovery_is_kept_a_week_and_not_offered(tmp_path, doc):
    root = tmp_path / "recovery"
    saver = autosave.Autosaver(doc, root)
    saver.save()
    (saver.folder / "session.json").write_text(json.dumps({"pid": 2**22 + 12345}))
    assert autosave.find_recoveries(root) == [saver.path]
    autosave.decline(saver.path)
    assert autosave.find_recoveries(root) == []
    assert autosave.prune(root) == 0 and saver.path.exists()
    assert autosave.prune(root, now=time.time() + 8 * 24 * 3600) == 1 and not saver.folder.exists()


def test_bones_follow_the_skeletons_grid_in_and_out(tmp_path):
    """The studio's bones are on its skeleton's grid: a .bones drawn on another grid is mapped onto it
    when loaded, and saved bones record the grid, so another tool reads them where they are (#35)."""
    from volanim_core.geometry import Geometry
    from volanim_core.rig.bones import BoneSkeleton
    from volanim_core.skeleton.points import Skeleton
    from volanim_studio.model import Document

    cubes = Geometry((0.5, 0.5, 0.5), (-40, -25, -900))
    doc = Document()
    doc.set_skeleton(Skeleton([[10, 10, 10], [20, 10, 10]], [2.0, 2.0], [0.9, 0.8], "euclid", cubes))
    drawn = BoneSkeleton({"A": (5, 5, 5), "B": (10, 5, 5)}, [], Geometry((1, 1, 1), (-40, -25, -900)))
    io.write_bones(tmp_path / "drawn.bones", drawn)
    doc.bone_edits.load_bones(tmp_path / "drawn.bones")
    assert np.allclose(doc.bones.joints["B"], (20, 10, 10))  # 10 mm from the origin: 20 cubes of 0.5 mm
    doc.bone_edits.save_bones(tmp_path / "saved.bones")
    assert io.read_bones(tmp_path / "saved.bones").geometry == cubes


# ---------------------------------------------------------------- #83: autosave that never lags
def test_a_held_drag_and_the_edits_before_it_are_on_disk_after_one_poll(tmp_path, doc):
    """The old autosave skipped every save while a slider was held: six renames and a held drag were lost
    to a kill. Now the poll after a change writes it (on the writer thread), drag or not."""
    saver = autosave.Autosaver(doc, tmp_path / "recovery")
    make_generation(doc, 5)
    for i, joint in enumerate(["R_ELBOW", "L_KNEE", "R_KNEE", "R_WRIST", "L_ANKLE", "R_ANKLE"]):
        doc.bone_edits.rename_joint(joint, f"RENAMED{i}")
    doc.settings.dragging = True  # a slider is held ...
    arm = doc.bones.index("L_UPPERARM")
    doc.pose.set_angles(arm, (0, 30, 0))  # ... and has moved: a merged step of an unfinished drag
    assert saver.poll() and saver.writing or saver.written == 1
    saver.wait()
    data = read_project(saver.path)
    assert sum(j.startswith("RENAMED") for j in io.read_bones(data["bones"]).joints) == 6
    assert np.allclose(data["state"]["pose"][0][("L_SHOULDER", "L_ELBOW")], (0, 30, 0))
    doc.pose.set_angles(arm, (0, 45, 0))  # the drag goes on: the next poll has its latest value
    assert saver.poll()
    saver.wait()
    assert np.allclose(read_project(saver.path)["state"]["pose"][0][("L_SHOULDER", "L_ELBOW")], (0, 45, 0))
    assert saver.caught_up and not saver.poll()  # nothing changed: nothing written


def test_a_snapshot_is_the_session_at_the_moment_it_was_taken(tmp_path, doc):
    """The writer thread formats a snapshot while the user goes on editing: what it writes is the
    moment the snapshot was taken, whatever the document became since."""
    from volanim_studio.model.project import snapshot, write_snapshot

    make_generation(doc, 9)
    path = tmp_path / "p.volanim"
    snap = snapshot(doc, path)
    make_generation(doc, 3)  # bones replaced, attachments changed in place
    doc.pose.set_angles(0, (10, 0, 0))
    write_snapshot(snap, path)
    assert generation_on_disk(path) == 9
    assert read_project(path)["state"]["pose"] == ({}, {})


def test_an_empty_session_is_never_autosaved_nor_offered(tmp_path):
    """A session killed while the recovery question was up was offered at the next start, and restoring it
    (0 bones) deleted the real one behind it."""
    from volanim_studio.model import Document

    root = tmp_path / "recovery"
    empty = Document()
    saver = autosave.Autosaver(empty, root, background=False)
    empty.settings.colour_by = "dt"  # the view changed, nothing was made
    assert not saver.poll() and not saver.path.exists() and saver.caught_up
    # an older studio's autosave of an empty session: pruned, never offered
    old = root / "4194304-1"
    old.mkdir()
    (old / "session.json").write_text(json.dumps({"pid": 2**22}))
    Document().write_project(old / autosave.RECOVERY_FILE)
    assert autosave.find_recoveries(root) == []
    assert autosave.prune(root) == 1 and not old.exists()


def test_an_unreadable_autosave_is_kept_and_offered_with_its_time(tmp_path):
    root = tmp_path / "recovery"
    damaged = root / "4194305-1"
    damaged.mkdir(parents=True)
    (damaged / "session.json").write_text(json.dumps({"pid": 2**22 + 1}))
    (damaged / autosave.RECOVERY_FILE).write_text("{not json")
    assert autosave.prune(root) == 0 and autosave.find_recoveries(root) == [damaged / autosave.RECOVERY_FILE]
    assert "could not be read" in autosave.describe(damaged / autosave.RECOVERY_FILE)


def test_the_recovery_question_says_what_each_autosave_holds(tmp_path, doc):
    saver = autosave.Autosaver(doc, tmp_path / "recovery")
    doc.demo_name = "mannequin"
    make_generation(doc, 7)
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0, -30, 0))
    doc.timeline.set_key(0)
    saver.save()
    text = autosave.describe(saver.path)
    assert text.endswith(": mannequin, 18 bones, 8 attachments, a pose, 1 key"), text
    (saver.folder / autosave.SUMMARY).unlink()  # an older studio's autosave: read from the project
    assert autosave.describe(saver.path).endswith(": mannequin, 18 bones, 8 attachments, a pose, 1 key")


def test_a_save_taken_from_a_document_since_replaced_is_not_adopted(tmp_path):
    """A save finishing after another volume or project was opened writes its files, but the new document
    does not take its path (Ctrl+S would have overwritten the old project with the new volume)."""
    from volanim_studio.model.project import write_save

    doc = Document()
    doc.bone_edits.set_bones(samples.mannequin_bones())
    save = doc.take_save(tmp_path / "a")
    doc.reset()
    assert not doc.adopt_save(save, write_save(save)) and doc.project_path is None
    assert save.path == tmp_path / "a.volanim" and save.path.exists()
