"""
The skeleton at three thinness levels
=====================================

``skeletonize`` gives every voxel of the object a *thinness*: its distance to the background less the mean
of its 26 neighbours'. The points at or above a level are the skeleton at that level, so one file holds every
resolution, coarse to fine (the studio's thinness slider). Here the mannequin at the three levels of the
thesis's Fig 5.17, read in its units: a third of them for our Euclidean thinness.
"""

import matplotlib.pyplot as plt

from volanim_core import samples
from volanim_core.skeleton.skeletonize import skeletonize

body = samples.load("mannequin")
skeleton = skeletonize(body.mask, min_thinness=0.0)  # every point down to 0: filter below
print(f"{len(skeleton)} points, thinness {skeleton.thinness.min():.2f} .. {skeleton.thinness.max():.3f}")

fig, axes = plt.subplots(1, 3, figsize=(9, 6), sharey=True)
for ax, level in zip(axes, (1.50, 1.35, 1.10)):
    keep = skeleton.thinness >= level / 3
    x, y, z = skeleton.points[keep].T
    ax.scatter(x, z, s=1, c=y, cmap="viridis_r")  # seen from the front, coloured by depth
    ax.set_title(f"thinness >= {level / 3:.2f}\n{keep.sum()} points")
    ax.set_aspect("equal")
    ax.axis("off")
plt.tight_layout()
