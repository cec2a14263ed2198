"""The rig: a bone skeleton and the skeleton points attached to it, posed frame by frame.

    bones.py ........ joints and bones in root order (``.bones``), hierarchy
    connectivity.py . points per bone (``.connect``), matrices per bone (``.trans``/``.tskel``)
    attach.py ....... attach points to bones: nearest, path inside the volume, geodesic
    autorig.py ...... propose bones from the skeleton: curve_skeleton.py (the tree), tree_walks.py (its
                      paths and bends), templates.py (names)
    pose.py ......... forward kinematics: rotations about joints -> one 4x4 matrix per bone
    tskel_tools.py .. the old pipeline's little tools on frames (connect2tskel, sorttskel, ...)
"""
