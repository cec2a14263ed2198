"""
Uncoil a colon: a chain of bones laid straight
==============================================

The thesis's section 5.3 uncoils a colon. :func:`~volanim_core.rig.straighten.straighten` turns each bone
of a chain by its least rotation onto the chain's principal axis, lengths kept, the first joint in place;
the curved-tube sample (a tube bent through half a circle, 8 bones) comes out straight.
"""

import matplotlib.pyplot as plt
import numpy as np

import volanim_core
from volanim_core import samples
from volanim_core.reconstruct import reconstruct
from volanim_core.render.bone_colours import label_table
from volanim_core.rig.straighten import straighten
from volanim_core.skeleton.skeletonize import skeletonize

tube = samples.load("curved-tube")
attached, _ = volanim_core.connect(skeletonize(tube.mask), tube.bones)
matrices, axis, chain = straighten(tube.bones)
print(f"{len(chain)} bones laid along {np.round(axis, 3)}")

table = label_table(len(tube.bones))
fig, axes = plt.subplots(2, 1, figsize=(8, 5))
for ax, mats, title in zip(axes, (np.tile(np.eye(4), (len(tube.bones), 1, 1)), matrices), ("curved", "straight")):
    recon = reconstruct(attached.posed(mats), mode="bone")
    v = recon.volume
    nearest = np.where((v > 0).any(axis=1), (v > 0).argmax(axis=1), -1)  # seen along y: the bend's plane
    x, z = np.nonzero(nearest >= 0)
    picture = np.full(nearest.shape + (3,), 24, np.uint8)
    picture[x, z] = table[v[x, nearest[x, z], z]]
    ax.imshow(picture.transpose(1, 0, 2)[::-1])
    ax.set_title(f"{title}: {int(np.count_nonzero(v))} voxels")
    ax.axis("off")
plt.tight_layout()
