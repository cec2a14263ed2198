"""Where the repository's files are, for tests at any depth of ``tests/``."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ASSETS = REPO / "assets"
WALK = REPO / "src" / "volanim_core" / "sample_data" / "walk.bvh"  # the real clip of ../shared/data, MIT
GLTF = REPO / "tests" / "data" / "gltf"  # a real VRM animation, test.vrma (tests/data/README.md)
FOX = REPO / "src" / "volanim_core" / "sample_data" / "Fox.glb"  # Khronos' glTF sample Fox, CC BY 4.0
HUESITOS = REPO / "src" / "volanim_core" / "sample_data" / "huesitos.fbx"  # assimp's FBX test model, BSD
FBX = REPO / "tests" / "data" / "fbx"  # assimp's animation_with_skeleton.fbx (tests/data/README.md)
