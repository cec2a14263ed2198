"""The README's auto-rig pictures (#62): one click's proposal on creatures nobody templated, then a limb turned.

    docs/autorig-creatures.png   a row per body (pyvista's ant, trimesh's rabbit, Spot the cow, Bob, the
                                 frog): its rest pose re-grown in bone mode, coloured by the proposal's
                                 bones, the bones drawn over it; beside it, every leaf bone bent 45
                                 degrees about the line of sight at once, re-grown, with the
                                 verdict `volanim report` gives that pose

Every body goes the README's way: voxelized at 160 voxels along its longest side (the frog: its own
scan), skeletonized, `autorig`, connected by pieces with the ownership and stray flesh hung on (autorig
--connect's default), posed from ownership (the default). Same renderer and camera for both panels of a row.

Run: make screenshots   (or .venv/bin/python docs/make_autorig_pictures.py)
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "benchmarks"))

BODIES = {"ant": "top", "rabbit": "side", "spot": "side", "bob": "three-quarter", "frog": "top"}  # -> view
SIZE = (360, 300)


def _bones_mesh(bones, matrices=None):
    import pyvista as pv

    from volanim_core.rig.pose import posed_joints

    joints = posed_joints(bones, matrices) if matrices is not None else bones.joints
    lines = pv.MultiBlock()
    for b in bones.bones:
        lines.append(pv.Tube(pointa=joints[b.proximal], pointb=joints[b.distal], radius=1.2))
    return lines.combine()


def row(name: str, view: str) -> np.ndarray:
    from bench_autorig_bodies import body_mask
    from scipy.spatial.transform import Rotation

    from volanim_core.reconstruct.checks import report
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.render.scene import Renderer, RenderSettings
    from volanim_core.render.views import named_view
    from volanim_core.rig.attach import connect
    from volanim_core.rig.autorig import autorig
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.curve_skeleton import balls
    from volanim_core.rig.ownership import ownership
    from volanim_core.rig.pose import pose_matrices, root_bones
    from volanim_core.rig.reach import hang_on
    from volanim_core.skeleton.skeletonize import skeletonize

    with tempfile.TemporaryDirectory() as tmp:
        mask, _ = body_mask(name, Path(tmp))
    skel = skeletonize(mask)
    bones = autorig(skel).bones
    conn, _ = connect(skel, bones, method="pieces", mask=balls(skel))
    # as autorig --connect writes it: the ownership of the body the spheres re-grow, stray flesh hung on
    conn = conn.with_ownership(hang_on(ownership(balls(skel), conn))[0])
    leaves = [bones.bones[i].label for i in bones.leaves()]
    rest = pose_matrices(bones, {})
    lo0 = np.asarray(skel.points.min(axis=0), float) - skel.dt.max()
    hi0 = np.asarray(skel.points.max(axis=0), float) + skel.dt.max()
    look = named_view(view, lo0, hi0, aspect=SIZE[0] / SIZE[1])
    axis = np.subtract(look.focal_point, look.position)
    # bent about the line of sight: in the picture's plane, however the body lies
    turn = Rotation.from_rotvec(np.radians(45.0) * axis / np.linalg.norm(axis)).as_matrix()
    turned = pose_matrices(bones, {leaf: turn for leaf in leaves})
    verdict = report(conn, Trans(root_bones(bones), turned), bones=bones).verdict.split(":")[0]
    shown = [(reconstruct(conn.posed(rest), mode="bone"), None), (reconstruct(conn.posed(turned), mode="bone"),
                                                                   turned)]
    lo = np.min([np.asarray(r.origin) for r, _ in shown], axis=0)
    hi = np.max([np.asarray(r.origin) + np.array(r.volume.shape) - 1 for r, _ in shown], axis=0)
    camera = named_view(view, lo, hi, aspect=SIZE[0] / SIZE[1])
    out = []
    for rec, matrices in shown:
        r = Renderer(RenderSettings(camera, style="surface", preset="bone", size=SIZE, background="#1e1f24",
                                    title=f"{name}: {len(bones.bones)} bones" if matrices is None
                                    else f"all {len(leaves)} leaves bent 45°: {verdict}"))
        try:
            r.draw(rec.volume, rec.origin)
            for actor in r.plotter.renderer.GetActors():
                actor.GetProperty().SetOpacity(0.55)  # the bones show through the flesh
            r.plotter.add_mesh(_bones_mesh(bones, matrices), color="white", reset_camera=False, render=False)
            camera.apply(r.plotter.renderer.GetActiveCamera())
            out.append(np.asarray(r.plotter.screenshot(return_img=True), np.uint8)[..., :3].copy())
        finally:
            r.close()
    return np.concatenate(out, axis=1)


def main() -> None:
    from skimage import io as skio

    from volanim_core.render.scene import prefer_egl_without_display

    prefer_egl_without_display()
    out = HERE / "autorig-creatures.png"
    skio.imsave(out, np.concatenate([row(n, v) for n, v in BODIES.items()], axis=0), check_contrast=False)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
