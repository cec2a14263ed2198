"""Motion onto the bone skeleton: motion capture, retargeting, keyframes, joint positions.

    bvh.py .......... the BVH reader and forward kinematics over all frames at once
    presets.py ...... naming schemes (Mixamo, CMU, ours): which joint name means which body part
    body.py, kind.py  a clip's body read from its shape and motion, names aside: parts, up, facing; biped or not
    retarget.py ..... BVH joints -> our bones: mapping, axes, units, rest-pose alignment; a .trans per frame
    plausible.py .... is a retargeted clip a person? checks on the posed joints before anything is written
    keyframes.py .... per-bone slerp between pose keys (``volanim keys``, the studio's timeline)
    keys_files.py ... ``.keys`` text; frame_files.py: one ``.trans`` (and ``.tskel``) per frame on disk
    bvh_export.py ... our bones and their motion as a BVH clip, for an animation package
    positions.py .... bone matrices from joint positions per frame (the thesis's ivskelgetrot)
    markers.py ...... marker data -> joint positions; c3d_layout.py: what a C3D file says of itself
"""
