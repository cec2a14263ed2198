"""
Rigid and smooth joints against the true shape
==============================================

With rigid joints each skeleton point follows one bone, so a joint bent far opens a crack on its outside
and piles flesh on its inside. Smooth joints blend: a point near the joint moves by a weighted mix of its
bones' motions. The mannequin is built from capsules, so its true shape in any pose can be painted
(:func:`~volanim_core.posed_truth.posed_sample`) and each reconstruction scored against it, not judged by
eye. Here the left thigh swung 90 degrees forward, seen from the side through the left hip: the smooth joint
rounds the corner the capsules keep, and scores lower than the rigid one at this joint (the smooth-joints
tutorial measures every joint of both mannequins).
"""

import matplotlib.pyplot as plt
import numpy as np

import volanim_core
from volanim_core import samples
from volanim_core.posed_truth import posed_sample
from volanim_core.reconstruct import reconstruct
from volanim_core.reconstruct.shape import compare_shapes
from volanim_core.rig.pose import pose_matrices
from volanim_core.rig.skinning import Joints
from volanim_core.skeleton.skeletonize import skeletonize

body = samples.load("mannequin")
attached, _ = volanim_core.connect(skeletonize(body.mask), body.bones)
matrices = pose_matrices(body.bones, {"L_THIGH": (-90, 0, 0)})
truth = posed_sample("mannequin", matrices)
hip = body.bones.joints["L_HIP"]


def side_slice(volume, origin):
    """The slice x = the left hip's, seen from the side (y across, z up), on the rest grid's coordinates."""
    x = int(round(hip[0])) - origin[0]
    return volume[x, :, :].T[::-1] > 0, (origin[1], origin[1] + volume.shape[1], origin[2], origin[2] + volume.shape[2])


fig, axes = plt.subplots(1, 3, figsize=(10, 4.5), sharey=True)
shown = [("the true shape", truth.volume, truth.origin, None)]
for joints in ("rigid", "smooth"):
    recon = reconstruct(attached.posed(matrices, Joints(joints)), mode="binary")
    score = compare_shapes(recon.volume, truth.volume, ours_origin=recon.origin, truth_origin=truth.origin)
    shown.append((f"{joints}: Dice {score.dice:.4f}", recon.volume, recon.origin, score))
for ax, (title, volume, origin, _) in zip(axes, shown):
    picture, extent = side_slice(volume, np.asarray(origin))
    ax.imshow(picture, cmap="gray", extent=extent)
    ax.set_facecolor("black")  # outside the volume's grid is empty too
    ax.set_xlim(hip[1] - 60, hip[1] + 70)
    ax.set_ylim(hip[2] - 60, hip[2] + 50)
    ax.set_title(title)
plt.tight_layout()
