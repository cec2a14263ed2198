"""From a segmented volume to a multi-resolution skeleton and a hull.

    points.py ....... Skeleton: points, DT and thinness, sorted by decreasing thinness (``.mskel``)
    skeletonize.py .. distance transform (edt or 3-4-5 chamfer) + thinness
    _kernels.py ..... numba kernels of the two
    hull.py ......... the isosurface drawn around the cloud (VTK flying edges, lazily imported)
"""
