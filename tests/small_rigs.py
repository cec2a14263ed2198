"""Small bone skeletons and a joint oracle shared by the motion and io tests."""

from __future__ import annotations

import numpy as np

from volanim_core.rig.bones import Bone, BoneSkeleton


def posed_joints(bones: BoneSkeleton, mats: np.ndarray) -> dict[str, np.ndarray]:
    """Each joint moved by the matrix of a bone it starts or ends (all agree when the rig holds)."""
    out = {}
    for b, bone in enumerate(bones.bones):
        for j in (bone.proximal, bone.distal):
            out.setdefault(j, []).append(bones.joints[j] @ mats[b, :3, :3] + mats[b, 3, :3])
    for j, ps in out.items():
        assert np.allclose(ps, ps[0], atol=1e-6), f"joint {j} torn apart"
    return {j: ps[0] for j, ps in out.items()}


def arms_down() -> BoneSkeleton:
    """Our arm, hanging down (z up, facing -y): shoulder at the top, then elbow, wrist."""
    joints = {"PELVIS": (0, 0, 0), "L_SHOULDER": (2, 0, 10), "L_ELBOW": (2, 0, 4), "L_WRIST": (2, 0, -1)}
    return BoneSkeleton(joints, [Bone("PELVIS", "L_SHOULDER", "SPINE"), Bone("L_SHOULDER", "L_ELBOW", "L_UPPERARM"),
                                 Bone("L_ELBOW", "L_WRIST", "L_FOREARM")])
