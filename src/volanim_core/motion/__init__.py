"""Motion onto the bone skeleton: BVH motion capture, retargeting, keyframes (issue: Motion).

``bvh.py``: the BVH reader and forward kinematics over all frames at once.
Still to come: ``retarget.py`` (BVH joints -> our bones, rest-pose alignment),
``keyframes.py`` (per-bone slerp between pose keys). Each frame ends as a ``.trans``.
"""
