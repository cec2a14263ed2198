"""Motion clips by their kind: ``.bvh`` through :mod:`bvh_files`, glTF 2.0 (``.gltf``, ``.glb``, VRM
animations ``.vrma``) through :mod:`gltf_files`, FBX through :mod:`fbx_files` (assimp). Every caller that
reads a clip (``bvh2trans``, ``sequence``, the demo, the studio's timeline and projects) comes through
:func:`read_clip`, so each takes every kind.

    path --suffix--> .bvh: read_bvh           (one clip a file; ``animation`` must be None)
                     .gltf .glb .vrma: read_gltf(animation: a name or index; None: the first)
                     .fbx: read_fbx(animation: the same), through assimp
"""

from __future__ import annotations

from pathlib import Path

from volanim_core.io.bvh_files import Motion

GLTF_SUFFIXES = (".gltf", ".glb", ".vrma")
CLIP_SUFFIXES = (".bvh", ".fbx", *GLTF_SUFFIXES)
#: the file dialogs' filter
CLIP_FILTER = "Motion clips (*.bvh *.gltf *.glb *.vrma *.fbx)"


def is_clip(path) -> bool:
    return Path(path).suffix.lower() in CLIP_SUFFIXES


def clip_animations(path) -> list[str]:
    """The animations a clip file holds, to pick one (a BVH file holds one, named by the file)."""
    if Path(path).suffix.lower() in GLTF_SUFFIXES:
        from volanim_core.io.gltf_files import animation_names, load_gltf

        return animation_names(load_gltf(path))
    if Path(path).suffix.lower() == ".fbx":
        from volanim_core.io.fbx_files import animation_names, load_fbx

        return animation_names(load_fbx(path))
    return [Path(path).stem]


def read_clip(path, animation: str | int | None = None) -> Motion:
    """The clip in ``path`` (its kind from its suffix), ``animation`` picking one of a glTF file's."""
    suffix = Path(path).suffix.lower()
    if suffix in GLTF_SUFFIXES:
        from volanim_core.io.gltf_files import read_gltf

        return read_gltf(path, animation)
    if suffix == ".fbx":
        from volanim_core.io.fbx_files import read_fbx

        return read_fbx(path, animation)
    from volanim_core.io.bvh_files import read_bvh

    if animation is not None:
        raise ValueError(f"{Path(path).name}: a BVH file holds one clip; --animation picks one of a glTF or FBX file's")
    return read_bvh(path)
