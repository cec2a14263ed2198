"""
A motion-capture clip on the mannequin's bones
==============================================

:func:`~volanim_core.io.bvh_files.read_bvh` reads a BVH clip (here the real walk, MIT); ``Retarget`` binds it
to our bones (names matched, axes and units found) and gives each frame's matrices, which pose the bones as
any ``.trans`` does. The plot follows both ankles through the clip, and draws the posed bones of four frames.
"""

import matplotlib.pyplot as plt
import numpy as np

from volanim_core import samples
from volanim_core.io.bvh_files import read_bvh
from volanim_core.motion.retarget import Retarget
from volanim_core.rig.pose import posed_joints

bones = samples.load("mannequin").bones
clip = read_bvh(samples.walk_clip())
walk = Retarget.build(bones, clip)
frames = np.arange(0, clip.frames, 4)
matrices = walk.matrices(frames)
print(f"{clip.frames} frames at {1 / clip.frame_time:.0f} fps onto {len(bones)} bones")

ankles = {side: np.array([posed_joints(bones, m)[f"{side}_ANKLE"] for m in matrices]) for side in ("L", "R")}
fig, (ax_t, ax_b) = plt.subplots(1, 2, figsize=(10, 4.5), gridspec_kw={"width_ratios": [1.4, 1]})
for side, points in ankles.items():
    ax_t.plot(frames * clip.frame_time, points[:, 2], label=f"{side} ankle height")
ax_t.set_xlabel("seconds")
ax_t.set_ylabel("voxels")
ax_t.legend()
for k, colour in zip(np.linspace(0, len(frames) - 1, 4).astype(int), plt.cm.viridis(np.linspace(0, 1, 4))):
    joints = posed_joints(bones, matrices[k])
    for b in bones.bones:
        (x0, _, z0), (x1, _, z1) = joints[b.proximal], joints[b.distal]
        ax_b.plot([x0, x1], [z0, z1], color=colour)
ax_b.set_aspect("equal")
ax_b.set_title("posed bones, seen from the front")
plt.tight_layout()
