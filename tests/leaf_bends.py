"""Every leaf bone of a proposal bent and judged: the poses `volanim report` does not call healthy."""

from __future__ import annotations

from volanim_core.reconstruct.checks import report
from volanim_core.rig.attach import connect
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.curve_skeleton import balls
from volanim_core.rig.pose import bend_across, pose_matrices, root_bones
from volanim_core.rig.skinning import Joints


def leaf_bends(skel, bones, angles=(45, 90), joints: str = "rigid") -> list[str]:
    """Each leaf bone bent by each of ``angles`` degrees (:func:`bend_across`), the skeleton connected by
    pieces as `autorig --connect` does: ``"LABEL ANGLE: verdict"`` of every pose not healthy."""
    conn = connect(skel, bones, method="pieces", mask=balls(skel))[0].with_joints(Joints(joints))
    return broken_bends(conn, bones, angles)


def broken_bends(conn, bones, angles=(45, 90)) -> list[str]:
    """Each leaf bone of ``bones`` bent by each of ``angles`` degrees (:func:`bend_across`) on ``conn`` as it
    is (its ownership, its joints): ``"LABEL ANGLE: verdict"`` of every pose `volanim report` calls not
    healthy, and of every pose that let a speck go (healthy, reconstruct/torn.py): these tests were written
    against specks torn off, and hold the rig to letting none go."""
    broken = []
    for k in bones.leaves():
        label = bones.bones[k].label
        for angle in angles:
            trans = Trans(root_bones(bones), pose_matrices(bones, {label: bend_across(bones, label, angle)}))
            rep = report(conn, trans, bones=bones)
            if not rep.healthy or rep.specks:
                broken.append(f"{label} {angle}: {rep.verdict.splitlines()[0]}; {len(rep.specks)} specks let go")
    return broken
