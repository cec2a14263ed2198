"""volanim core: volume animation without Qt.

    volume (.vol/.VOL/.vti/...) --volume--> mask --skeletonize--> Skeleton (.mskel)
    Skeleton + BoneSkeleton (.bones) --attach--> Connectivity (.connect)
    Connectivity + pose matrices (.trans) --> Tskel (.tskel) --reconstruct--> volume
"""

__version__ = "0.1.0"

# The studio's tools as functions, each named as its ``volanim`` command and taking the same options;
# imported on first use so that ``import volanim_core`` stays light (numba compiles on first call anyway).
_API = {
    "connect": "volanim_core.rig.attach",
    "autorig": "volanim_core.rig.autorig",
    "mirror": "volanim_core.rig.symmetry",
    "keys": "volanim_core.motion.keyframes",
    "report": "volanim_core.reconstruct.checks",
    "scan": "volanim_core.reconstruct.checks",
    "transforms": "volanim_core.reconstruct.displacement",
    "displacement": "volanim_core.reconstruct.displacement",
}
# Not ``reconstruct``: the subpackage of that name is this attribute once anything imports it, so a function
# there could not be reached; it is ``volanim_core.reconstruct.reconstruct``.
__all__ = ["__version__", *_API]


def __getattr__(name: str):
    if name in _API:
        import importlib

        return getattr(importlib.import_module(_API[name]), name)
    raise AttributeError(f"module 'volanim_core' has no attribute {name!r}")
