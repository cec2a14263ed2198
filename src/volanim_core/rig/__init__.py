"""The rig: a bone skeleton and the skeleton points attached to it, posed frame by frame.

    bones.py ........ joints and bones in root order (``.bones``), hierarchy
    connectivity.py . points per bone (``.connect``), matrices per bone (``.trans``/``.tskel``)
    nearest.py ...... each point's distance to every bone's segment; the nearest bone
    attach.py ....... attach points to bones: nearest, path inside the volume, geodesic, and the rules of
                      limb_tubes.py (fitted: flesh a limb cannot carry), pieces.py (a body in pieces) and
                      islands.py (each bone's flesh in one piece)
    ownership.py .... which bone owns each rest voxel (the rig's label volume): tubes fitted to each bone's
                      middle, each voxel to the tube that holds it deepest (_ownership_kernels.py); the
                      thin flesh a turned bone pushes forward (_thin_kernels.py); each bone's hull
                      from its slices' outlines (_hull_kernels.py); the tables a posed frame reads, made
                      from the labels' runs (_table_kernels.py);
                      specks.py gives a speck of one bone inside another's flesh to the flesh around it
                      (_speck_kernels.py);
                      reach.py names flesh that hangs from the body only through another limb's
    symmetry.py ..... one side's attachments mirrored to the other (L_/R_ names)
    autorig.py ...... propose bones from the skeleton: curve_skeleton.py (the tree), tree_walks.py (its
                      paths and bends), landmarks.py (shoulders and hips off the body), templates.py (names)
    pose.py ......... forward kinematics: rotations about joints -> one 4x4 matrix per bone; where joints go
    key_pose.py ..... a pose key: per bone, Euler angles and a shift (the .keys files' and the timeline's)
    straighten.py ... a chain of bones laid straight along its principal axis (the colon, section 5.3)
    skinning.py ..... smooth joints: blend weights per point (skin.py the Skin they make; thin_spheres.py
                      one-voxel spheres moved as the sphere that holds them); dual_quaternion.py the blend
    tskel_tools.py .. the old pipeline's little tools on frames (connect2tskel, sorttskel, ...)
"""
