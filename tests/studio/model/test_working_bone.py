"""The working bone is a bone, not a row (#61, item 1).

After dragging rows to reorder the bones or *Open connections…* with another root order, the selected
working bone kept its row number and silently became another bone (HEAD turned into L_CLAVICLE): the
next cube or lasso connect attached points to the wrong bone. Every sequence of reorders, connection
files, joint renames, undos and redos here keeps the working bone the same bone (by its name, which
none of them changes), or drops it when the bone is gone.
"""

from __future__ import annotations

import copy

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from volanim_core import io, samples
from volanim_studio.model import Document
from volanim_studio.model.bone_edits import followed_selection


def fresh() -> Document:
    d = Document()
    d.bone_edits.set_bones(samples.mannequin_bones())
    d.undo.clear()
    return d


def working_name(doc):
    w = doc.working_bone
    return None if w is None else doc.bones.bones[w].label


def test_reorder_keeps_the_working_bone():
    """The walkthrough's case: HEAD selected, the bones reordered, HEAD is still the working bone."""
    doc = fresh()
    doc.select_bones([doc.bones.index("HEAD")])
    order = list(range(len(doc.bones)))
    order.insert(3, order.pop(1))  # HEAD dragged below L_CLAVICLE
    doc.bone_edits.set_root_order(order)
    assert working_name(doc) == "HEAD"
    doc.undo.undo()
    assert working_name(doc) == "HEAD" and doc.working_bone == 1
    doc.undo.redo()
    assert working_name(doc) == "HEAD" and doc.working_bone == 3


def test_open_connections_keeps_the_working_bone_and_drops_a_gone_one(tmp_path):
    doc = fresh()
    doc.select_bones([doc.bones.index("HEAD"), doc.bones.index("L_HAND")])
    reversed_bones = samples.mannequin_bones()
    reversed_bones.bones = reversed_bones.bones[::-1]
    io.write_connections(tmp_path / "r.connections", reversed_bones)
    doc.bone_edits.load_connections(tmp_path / "r.connections")
    assert [doc.bones.bones[i].label for i in doc.selected_bones] == ["HEAD", "L_HAND"]
    without_head = samples.mannequin_bones()
    without_head.bones = [b for b in without_head.bones if b.name != "HEAD"]
    io.write_connections(tmp_path / "h.connections", without_head)
    doc.bone_edits.load_connections(tmp_path / "h.connections")
    assert [doc.bones.bones[i].label for i in doc.selected_bones] == ["L_HAND"]


def test_a_renamed_joint_keeps_the_bone_selected():
    doc = fresh()
    doc.select_bones([doc.bones.index("L_UPPERARM")])
    doc.bone_edits.rename_joint("L_ELBOW", "L_ELB")
    assert working_name(doc) == "L_UPPERARM"
    doc.undo.undo()
    assert working_name(doc) == "L_UPPERARM"


OPS = st.lists(st.one_of(
    st.tuples(st.just("reorder"), st.permutations(range(18))),
    st.tuples(st.just("connections"), st.permutations(range(18)), st.integers(0, 17), st.booleans()),
    st.tuples(st.just("rename"), st.integers(0, 18)),
    st.tuples(st.just("undo")), st.tuples(st.just("redo")),
), max_size=8)


@settings(max_examples=40, deadline=None)
@given(start=st.integers(0, 17), ops=OPS)
def test_no_sequence_turns_the_working_bone_into_another(tmp_path_factory, start, ops):
    doc = fresh()
    folder = tmp_path_factory.mktemp("c")
    doc.select_bones([start])
    name = working_name(doc)
    for k, (op, *args) in enumerate(ops):
        if op == "reorder" and len(args[0]) == len(doc.bones):
            doc.bone_edits.set_root_order(list(args[0]))
        elif op == "connections":
            perm, drop, dropping = args
            b = copy.deepcopy(doc.bones)  # the joints loaded now (a rename may have renamed some)
            b.bones = [b.bones[i] for i in perm if i < len(b.bones) and not (dropping and i == drop)]
            io.write_connections(folder / f"{k}.connections", b)
            doc.bone_edits.load_connections(folder / f"{k}.connections")
        elif op == "rename":
            joints = sorted(doc.bones.joints)
            doc.bone_edits.rename_joint(joints[args[0] % len(joints)], f"J{k}X")
        elif op == "undo":
            doc.undo.undo()  # nothing to undo: None, no change
        elif op == "redo":
            doc.undo.redo()
        now = working_name(doc)
        if now is None:
            name = None  # the bone went (a connections file without it): the selection is empty, not another
        assert now == name, f"after {op}: the working bone {name} became {now}"
        assert doc.working_bone is None or 0 <= doc.working_bone < len(doc.bones)


def test_followed_selection_by_place_when_names_change():
    old = samples.mannequin_bones()
    new = samples.mannequin_bones()
    new.joints["X"] = new.joints.pop("HEAD")
    new.bones = [type(b)(b.proximal, "X" if b.distal == "HEAD" else b.distal, b.name) for b in new.bones][::-1]
    assert followed_selection(old, new, (1,)) == (len(new.bones) - 2,)
    assert np.array_equal(new.joints["X"], old.joints["HEAD"])
