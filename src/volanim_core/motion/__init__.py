"""Motion onto the bone skeleton: motion capture, retargeting, keyframes, joint positions.

Reading and writing their files is io's (io/bvh_files.py, io/keys_files.py, io/frame_files.py,
io/mapping_files.py, io/positions_files.py, io/marker_files.py); here is what the motion means.

    presets.py ...... naming schemes (Mixamo, CMU, ours): which joint name means which body part
    body.py, kind.py  a clip's body read from its shape and motion, names aside: parts, up, facing; biped or not
    chains.py ....... a creature's figure as chains (legs by pair and side, spine, head, tail), read alike from
                      a clip and a rig, and matched chain to chain: clips of its kind onto any auto-rig
    retarget.py ..... BVH joints -> our bones: mapping, axes, units, rest-pose alignment; a .trans per frame
    plausible.py .... is a retargeted clip a person (or the rig's creature)? checks on the posed joints
    keyframes.py .... per-bone slerp between pose keys (``volanim keys``, the studio's timeline)
    positions.py .... bone matrices from joint positions per frame (the thesis's ivskelgetrot)
    markers.py ...... marker data -> joint positions in our bones' space (the map, the fit)
"""
