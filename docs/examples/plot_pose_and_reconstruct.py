"""
Pose a volume and grow it back
==============================

The whole job in a few calls: the bundled mannequin, its skeleton (distance transform + thinness), each
point attached to its nearest bone, the left upper arm raised 60 degrees at the shoulder, and the volume
re-grown in that pose. Each voxel keeps the colour of the bone that carried it (``mode="bone"``).
"""

import matplotlib.pyplot as plt
import numpy as np

import volanim_core
from volanim_core import samples
from volanim_core.reconstruct import reconstruct
from volanim_core.render.bone_colours import label_table
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import pose_matrices, root_bones
from volanim_core.rig.tskel_tools import connect_to_tskel
from volanim_core.skeleton.skeletonize import skeletonize

body = samples.load("mannequin")
skeleton = skeletonize(body.mask, min_thinness=0.5)
attached, report = volanim_core.connect(skeleton, body.bones)
print(f"{len(skeleton)} skeleton points on {len(body.bones)} bones")

# %%
# A pose is one 4x4 matrix per bone; ``pose_matrices`` makes them from angles at each bone's proximal joint.
pose = pose_matrices(body.bones, {"L_UPPERARM": (0, -60, 0)})
roots = root_bones(body.bones)
rest = reconstruct(connect_to_tskel(attached, Trans(roots, pose_matrices(body.bones, {}))), mode="bone")
posed = reconstruct(connect_to_tskel(attached, Trans(roots, pose)), mode="bone")


def front(recon):
    """The reconstruction seen from the front: the nearest label along y, in its bone's colour."""
    v = recon.volume
    first = np.where((v > 0).any(axis=1), (v > 0).argmax(axis=1), -1)
    x, z = np.nonzero(first >= 0)
    picture = np.full(first.shape + (3,), 24, np.uint8)
    picture[x, z] = label_table(len(body.bones))[v[x, first[x, z], z]]
    return picture.transpose(1, 0, 2)[::-1]


fig, axes = plt.subplots(1, 2, figsize=(8, 6))
for ax, recon, title in zip(axes, (rest, posed), ("rest", "L_UPPERARM raised 60 degrees")):
    ax.imshow(front(recon))
    ax.set_title(title)
    ax.axis("off")
plt.tight_layout()
