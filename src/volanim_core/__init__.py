"""volanim core: volume animation without Qt.

    volume (.vol/.VOL/.vti/...) --volume--> mask --skeletonize--> Skeleton (.mskel)
    Skeleton + BoneSkeleton (.bones) --attach--> Connectivity (.connect)
    Connectivity + pose matrices (.trans) --> Tskel (.tskel) --reconstruct--> volume
"""

__version__ = "0.1.0"
