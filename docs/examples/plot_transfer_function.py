"""
A transfer function over a sampled reconstruction
=================================================

A :class:`~volanim_core.transfer_function.TransferFunction` maps each value to a colour and an opacity,
linear between its points (the studio's editor, a ``.tf`` file, ``volanim render --tf``). Here the posed
mannequin re-grown from its scan's values (``mode="sampled"``) and composited front to back along y with
NumPy alone: flesh faint, skin clear, bones opaque ivory.
"""

import matplotlib.pyplot as plt
import numpy as np

import volanim_core
from volanim_core import samples
from volanim_core.reconstruct import reconstruct
from volanim_core.rig.pose import pose_matrices
from volanim_core.skeleton.skeletonize import skeletonize
from volanim_core.transfer_function import TransferFunction

body = samples.load("mannequin")
attached, _ = volanim_core.connect(skeletonize(body.mask), body.bones)
posed = reconstruct(attached.posed(pose_matrices(body.bones, {"L_UPPERARM": (0, -60, 0), "R_THIGH": (30, 0, 0)})),
                    mode="sampled", source=body.volume)
tf = TransferFunction([0, 80, 90, 130, 165, 200, 215, 230, 250],
                      [[0, 0, 0, 0], [0, 0, 0, 0], [0.95, 0.85, 0.35, 0.02], [0.8, 0.2, 0.15, 0.05],
                       [0.9, 0.45, 0.4, 0.06], [0.9, 0.5, 0.45, 0.0], [0.9, 0.5, 0.45, 0.0],
                       [0.95, 0.92, 0.8, 0.9], [1, 1, 1, 1]])

rgba = tf(posed.volume)  # (X, Y, Z, 4)
picture, left = np.zeros(rgba.shape[::2][:1] + rgba.shape[2:3] + (3,)), np.ones(rgba.shape[::2][:1] + rgba.shape[2:3])
for y in range(rgba.shape[1]):  # front (y = 0) to back: each slab adds what light is left times its opacity
    alpha = rgba[:, y, :, 3]
    picture += (left * alpha)[..., None] * rgba[:, y, :, :3]
    left *= 1 - alpha

fig, (ax_tf, ax_pic) = plt.subplots(1, 2, figsize=(10, 5), gridspec_kw={"width_ratios": [1.3, 1]})
values = np.linspace(0, 255, 256)
ax_tf.hist(posed.volume[posed.volume > 0], bins=128, range=(0, 255), color="0.7", log=True)
ax_tf.twinx().plot(tf.values, tf.rgba[:, 3], "o-", color="k")
ax_tf.scatter(values, np.zeros_like(values), c=np.clip(tf(values)[:, :3], 0, 1), marker="s", s=20)
ax_tf.set_xlabel("value (histogram: log counts; line: opacity)")
ax_pic.imshow(np.clip(picture.transpose(1, 0, 2)[::-1] + 0.1 * left.T[::-1, :, None], 0, 1))
ax_pic.axis("off")
plt.tight_layout()
