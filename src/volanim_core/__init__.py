"""volanim core: volume animation without Qt.

    volume (.vol/.VOL/.vti/...) --volume--> mask --skeletonize--> Skeleton (.mskel)
    Skeleton + BoneSkeleton (.bones) --attach--> Connectivity (.connect)
    Connectivity + pose matrices (.trans) --> Tskel (.tskel) --reconstruct--> volume

The packages, lowest layer first (the ``core-layers`` contract in pyproject.toml keeps each importing
only those below it): skeleton/, rig/, io/, colour/, reconstruct/ and motion/, sequence/ and render/,
cli/. The modules beside them:

    errors.py ............ the exceptions every layer raises (FormatError names file and line)
    limits.py ............ input size limits, checked from a header before anything is allocated
    progress.py .......... progress and cancel without Qt (Reporter, TextProgress)
    geometry.py .......... where each voxel is in physical space: spacing, origin, direction
    modes.py ............. the reconstruction modes' names
    camera.py ............ a camera as plain data; transfer_function.py: value -> colour and opacity
    isosurface.py ........ an isosurface as plain arrays (VTK's flying edges) for code below render/
    voxel_faces.py ....... the faces between filled and empty voxels as plain arrays: the live preview's
                           surface (numba kernels in _face_kernels.py)
    _run_kernels.py ...... a grid's rows as runs and their 26-connected pieces: the breakage report's and
                           ownership's specks' labelling
    memo.py .............. a few recent results kept by a hash of their inputs
    parallel.py .......... where many tasks run: this process, a spawn pool, or a Dask cluster
    cluster_config.py .... a Dask cluster started from a file (dask-ctl's spec): --cluster-config
    volume.py ............ the old pipeline's volume tools as pure functions, and the value helpers
    mannequin_body.py .... the mannequin's analytic body: bones and a tapered capsule per bone
    posed_truth.py ....... the mannequin's true shape in any pose (what volanim compare scores against)
    samples.py ........... demo data: the mannequins, the aliascube, the frog; ant_sample.py: the ant
    warmup.py ............ every numba kernel compiled once on tiny inputs
    pipeline_demo.py ..... the headless demo behind make demo and volanim demo
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
