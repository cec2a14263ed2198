"""The session is one state, saved whole, and undo means exactly the user's edits (issue #37).

A hypothesis state machine drives a real Document through random edits (bones, attachments, poses,
drags, keys), view changes (thinness, settings, frame, mode, selection, camera), loads, saves,
reopenings, undos and redos. After each reopen every part of the state equals what was saved; after
each undo the edited state equals what it was before the undone edit, and a redo brings it back.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, precondition, rule

from volanim_core import io, samples
from volanim_core.skeleton.points import Skeleton
from volanim_studio.model import Document
from volanim_studio.model.document_state import ATTRIBUTES, PARTS
from volanim_studio.model.project import apply_project, read_project
from volanim_studio.model.settings import SETTINGS, Mode


def test_every_document_attribute_has_a_place_in_the_project_or_a_reason():
    """A property added to the Document later is saved, or says why not: no one has to remember."""
    attributes = set(vars(Document()))
    assert attributes - set(ATTRIBUTES) == set(), "place these in document_state.ATTRIBUTES"
    assert set(ATTRIBUTES) - attributes == set(), "stale entries in document_state.ATTRIBUTES"


def test_every_saved_setting_is_in_the_project_and_the_moment_s_state_is_not(tmp_path):
    doc = Document()
    doc.bone_edits.set_bones(samples.mannequin_bones())
    doc.settings.dragging = True
    doc.write_project(tmp_path / "p.volanim")
    data = json.loads((tmp_path / "p.volanim").read_text())
    assert set(data["settings"]) == {name for name, s in SETTINGS.items() if s.saved}
    assert "dragging" not in data["settings"] and {p.key for p in PARTS} <= set(data)


def test_a_thinness_of_minus_zero_is_saved_and_reopened_as_zero(tmp_path):
    """The example hypothesis drew (thinness -0.0): the reopened document held 0.0 while the saved file
    said -0.0. The document holds no -0.0 and a project writes numbers as their value
    (docs/formats.md#project)."""
    doc = Document()
    doc.set_skeleton(_skeleton())
    doc.thinness = 1.0
    doc.thinness = -0.0
    assert math.copysign(1, doc.thinness) == 1
    doc.save_project(tmp_path / "p.volanim")
    text = (tmp_path / "p.volanim").read_text()
    assert "-0.0" not in text and json.loads(text)["thinness"] == 0.0
    fresh = Document()
    apply_project(fresh, read_project(tmp_path / "p.volanim"), tmp_path / "p.volanim", reset=True)
    assert math.copysign(1, fresh.thinness) == 1 and whole_state(fresh) == whole_state(doc)


def _skeleton() -> Skeleton:
    rng = np.random.default_rng(7)
    pts = np.unique(rng.integers(0, 160, size=(120, 3)), axis=0)
    return Skeleton(pts, np.sqrt(rng.integers(1, 30, len(pts)).astype(float)), rng.normal(0.5, 1, len(pts))).sorted()


def _as_numbers(state: dict) -> dict:
    """``state`` as a saved file gives it back (JSON's types), compared as numbers, never as text: -0.0 is
    0.0 (a state compared as JSON text failed at random when hypothesis drew thinness -0.0)."""
    return json.loads(json.dumps(state, sort_keys=True, default=str))


def edited_state(doc) -> dict:
    """What undo restores: the bones, the attachments, the pose and the keys."""
    return _as_numbers({"joints": {k: [float(x) for x in v] for k, v in doc.bones.joints.items()},
                       "bones": [[b.proximal, b.distal, b.name] for b in doc.bones.bones],
                       "attachments": doc.attachments.bone.tolist(), "pose": doc.pose.to_json(),
                       "keys": doc.timeline.to_json()["keys"]})


def whole_state(doc) -> dict:
    """Everything a reopened project must give back, read off the document's attributes (not through
    document_state, which is under test)."""
    bones = doc.bones.bones
    return _as_numbers({"edited": edited_state(doc), "settings": doc.settings.as_dict(), "thinness": doc.thinness,
                       "symmetry_x": doc.symmetry_x, "timeline": doc.timeline.to_json(),
                       "selected": [[bones[i].proximal, bones[i].distal] for i in doc.selected_bones],
                       "joint": doc.picked_joint, "point": doc.picked_point, "camera": doc.camera_now(),
                       "frame": doc.settings.current_frame, "mode": str(doc.settings.mode),
                       "skeleton": doc.skeleton.points.tolist()})


angles = st.lists(st.integers(-180, 180), min_size=3, max_size=3)


class Session(RuleBasedStateMachine):
    """One user's session on a small skeleton and the mannequin's bones."""

    def __init__(self):
        super().__init__()
        self._tmp = tempfile.TemporaryDirectory(prefix="volanim-session-")
        self.folder = Path(self._tmp.name)
        self.saves = 0

    def teardown(self):
        self._tmp.cleanup()

    @initialize()
    def start(self):
        self.doc = Document()
        self.doc.set_skeleton(_skeleton())
        io.write_bones(self.folder / "m.bones", samples.mannequin_bones())
        self.doc.bone_edits.load_bones(self.folder / "m.bones")
        self.before: list[dict] = []  # the edited state before each step of the history
        self.exact: list[bool] = []  # False: a frame was shown since that step (its pose is the frame's)
        self.after: list[dict] = []  # ... and after each undone step (for redo)

    # ------------------------------------------------------------ edits
    def _edit(self, action) -> None:
        """Run one user action; if it made an undo step, remember the state before it."""
        state, edits = edited_state(self.doc), self.doc.undo.edits
        try:
            action()
        except ValueError:
            assert edited_state(self.doc) == state, "a refused edit changed the document"
            return
        self.doc.undo.seal()  # one action, one step (the window seals at every release and Enter)
        if self.doc.undo.edits != edits:
            self.before.append(state)
            self.exact.append(True)
            self.after.clear()

    @rule(i=st.integers(0, 40), j=st.integers(0, 40))
    def add_bone(self, i, j):
        pts = self.doc.skeleton.points
        self._edit(lambda: self.doc.bone_edits.add_bone(pts[i].astype(float), pts[j].astype(float)))

    @precondition(lambda self: len(self.doc.bones) > 1)
    @rule(i=st.integers(0, 30))
    def remove_bone(self, i):
        self._edit(lambda: self.doc.bone_edits.remove_bones([i % len(self.doc.bones)]))

    @precondition(lambda self: len(self.doc.bones))
    @rule(i=st.integers(0, 30), name=st.sampled_from(["A", "B", "L_X", "R_X"]))
    def rename_joint(self, i, name):
        joints = list(self.doc.bones.joints)
        self._edit(lambda: self.doc.bone_edits.rename_joint(joints[i % len(joints)], name))

    @precondition(lambda self: len(self.doc.bones))
    @rule(first=st.integers(0, 100), count=st.integers(1, 30), bone=st.integers(-1, 30))
    def attach(self, first, count, bone):
        n = len(self.doc.skeleton)
        b = -1 if bone < 0 else bone % len(self.doc.bones)
        self._edit(lambda: self.doc.attachments.assign(np.arange(first, first + count) % n, b))

    @precondition(lambda self: len(self.doc.bones))
    @rule(bone=st.integers(0, 30), a=angles)
    def type_angles(self, bone, a):
        self._edit(lambda: self.doc.pose.set_angles(bone % len(self.doc.bones), a, merge=False))

    @precondition(lambda self: len(self.doc.bones))
    @rule(bone=st.integers(0, 30), path=st.lists(angles, min_size=1, max_size=6))
    def drag(self, bone, path):
        """A slider held from press to release: every move merges into one step."""
        def held():
            self.doc.undo.seal()
            for a in path:
                self.doc.pose.set_angles(bone % len(self.doc.bones), a, merge=True)
        self._edit(held)

    @precondition(lambda self: len(self.doc.bones) and self.doc.timeline.clip is None)
    @rule(frame=st.integers(0, 60))
    def set_key(self, frame):
        self._edit(lambda: self.doc.timeline.set_key(frame))

    @precondition(lambda self: self.doc.timeline.keys)
    @rule(k=st.integers(0, 20))
    def delete_key(self, k):
        keys = sorted(self.doc.timeline.keys)
        self._edit(lambda: self.doc.timeline.delete_key(keys[k % len(keys)]))

    # ------------------------------------------------------- view state
    @rule(t=st.floats(-1, 3))
    def thinness(self, t):
        self.doc.thinness = t

    @rule(colour=st.sampled_from(["thinness", "dt", "bone"]), mode=st.sampled_from(list(Mode)),
          preview=st.sampled_from(["bone", "binary", "sampled"]), follow=st.booleans())
    def settings(self, colour, mode, preview, follow):
        s = self.doc.settings
        s.colour_by, s.mode, s.preview_mode, s.follow_body = colour, mode, preview, follow

    @rule(frame=st.integers(0, 60))
    def go_to_frame(self, frame):  # with keys the pose shows the frame: looking, not an edit
        before = self.doc.undo.edits
        self.doc.settings.current_frame = frame
        assert self.doc.undo.edits == before
        if self.doc.timeline.keys:
            self.exact = [False] * len(self.exact)

    @precondition(lambda self: len(self.doc.bones))
    @rule(bones=st.lists(st.integers(0, 30), max_size=3), point=st.integers(0, 200))
    def select(self, bones, point):
        self.doc.select_bones([b % len(self.doc.bones) for b in bones])
        self.doc.pick_point(point % len(self.doc.skeleton))
        joints = list(self.doc.bones.joints)
        self.doc.pick_joint(joints[point % len(joints)])

    @rule(d=st.floats(100, 5000), up=st.sampled_from([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]))
    def camera(self, d, up):
        pos = [80.0, 80.0 - d, 80.0] if up[2] else [80.0, 80.0, 80.0 + d]
        self.doc.set_camera({"position": pos, "focal_point": [80.0, 80.0, 80.0], "view_up": up})

    # ---------------------------------------------------- history, files
    @precondition(lambda self: self.doc.undo.can_undo)
    @rule()
    def undo(self):
        now = edited_state(self.doc)
        self.doc.undo.undo()
        if self.exact[-1]:
            assert edited_state(self.doc) == self.before[-1], "undo did not give back the state before the edit"
        else:  # a frame shown since: the replay without the edit shows that frame's pose
            assert _without_pose(edited_state(self.doc)) == _without_pose(self.before[-1])
            self._assert_pose_is_the_frame_s()
        self.before.pop()
        self.exact.pop()
        self.after.append(now)

    @precondition(lambda self: self.doc.undo.can_redo)
    @rule()
    def redo(self):
        self.before.append(edited_state(self.doc))
        self.exact.append(True)
        self.doc.undo.redo()
        again = self.after.pop()
        assert _without_pose(edited_state(self.doc)) == _without_pose(again), "redo did not give back the edit"
        if not self.doc.timeline.keys:
            assert edited_state(self.doc) == again, "redo did not give back the pose"

    def _assert_pose_is_the_frame_s(self):
        if self.doc.timeline.active:
            pose = self.doc.pose.to_json()
            self.doc.timeline.show_frame()  # looking again at the frame changes nothing
            assert _close(self.doc.pose.to_json(), pose), "the pose is not the frame's"

    @rule()
    def save_and_reopen(self):
        self.saves += 1
        path = self.folder / f"s{self.saves}.volanim"
        self.doc.save_project(path)
        saved = whole_state(self.doc)
        assert not self.doc.modified
        fresh = Document()
        apply_project(fresh, read_project(path), path, reset=True)
        assert whole_state(fresh) == saved, "the reopened project differs from what was saved"
        assert not fresh.undo.can_undo and not fresh.modified  # opening is not an edit
        self.doc = fresh
        self.before, self.exact, self.after = [], [], []

    @precondition(lambda self: len(self.doc.bones))
    @rule()
    def load_bones_file(self):
        """Opening a file is not an edit: the history starts after it."""
        io.write_bones(self.folder / "load.bones", self.doc.bones, self.doc.grid)
        self.doc.bone_edits.load_bones(self.folder / "load.bones")
        assert not self.doc.undo.can_undo and self.doc.modified
        self.before, self.exact, self.after = [], [], []

    @invariant()
    def history_matches(self):
        if hasattr(self, "doc"):
            assert self.doc.undo.can_undo == bool(self.before)


def _close(a: dict, b: dict) -> bool:
    """Two poses alike: a bone left out is at rest (zeros)."""
    for k in ("angles", "shifts"):
        ta, tb = ({tuple(r[:2]): np.array(r[2:]) for r in t[k]} for t in (a, b))
        if not all(np.allclose(ta.get(n, np.zeros(3)), tb.get(n, np.zeros(3)), atol=1e-6) for n in {*ta, *tb}):
            return False
    return True


def _without_pose(state: dict) -> dict:
    return {k: v for k, v in state.items() if k != "pose"}


TestRandomSessions = pytest.mark.slow(Session.TestCase)
TestRandomSessions.settings = settings(max_examples=25, stateful_step_count=30, deadline=None,
                                       suppress_health_check=[HealthCheck.too_slow])
