"""Motion onto the bone skeleton: BVH motion capture, retargeting, keyframes (issue: Motion).

Planned modules: ``bvh.py`` (reader + forward kinematics over all frames),
``retarget.py`` (BVH joints -> our bones, rest-pose alignment), ``keyframes.py``
(per-bone slerp between pose keys). Each frame ends as a ``.trans``.
"""
