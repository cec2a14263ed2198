"""The README's posed-shape pictures (#60): a pose reconstructed two ways beside the body's true shape.

    docs/raised-arm-nearest-fitted-truth.png   mannequin, L_UPPERARM raised 90 degrees, from the front
    docs/large-hip-nearest-fitted-truth.png    mannequin-large, R_THIGH flexed 120 degrees: the hip, from the
                                               front right

Each is three panels, bone mode coloured by bone: nearest-bone connect (today's default), the fitted
connect (rig/limb_tubes.py), and the capsules posed by the same matrices (posed_truth.py), all through the
same renderer and the same camera.

Run: make screenshots   (or .venv/bin/python docs/make_shape_pictures.py [FILE ...])
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent / "benchmarks"))

PICTURES = {  # file -> (sample, bone, rotation, view, the joint looked at (None: the whole body))
    "raised-arm-nearest-fitted-truth.png": ("mannequin", "L_UPPERARM", (0, -90, 0), "front", None),
    "large-hip-nearest-fitted-truth.png": ("mannequin-large", "R_THIGH", (-120, 0, 0), "right three-quarter",
                                           "R_HIP"),
}
CLOSE = 110  # voxels each way around the joint looked at
SIZE = (320, 480)


def panels(name: str, bone: str, rotation, view: str, joint: str | None) -> list[np.ndarray]:
    from bench_shape import default_connectivity

    from volanim_core import samples
    from volanim_core.posed_truth import posed_sample
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.render.scene import Renderer, RenderSettings
    from volanim_core.render.views import named_view
    from volanim_core.rig.pose import pose_matrices, posed_joints

    sample = samples.load(name)
    m = pose_matrices(sample.bones, {bone: rotation})
    truth = posed_sample(name, m)
    volumes = [(reconstruct(default_connectivity(sample, method).posed(m), mode="bone"))
               for method in ("nearest", "fitted")]
    shown = [(r.volume, np.asarray(r.origin)) for r in volumes] + [(truth.part, np.asarray(truth.origin))]
    lo = np.min([o for _, o in shown], axis=0)
    hi = np.max([o + np.array(v.shape) - 1 for v, o in shown], axis=0)
    if joint:
        at = np.asarray(posed_joints(sample.bones, m)[joint])
        lo, hi = at - CLOSE, at + CLOSE
    # one camera for all three; "right ..." is the view mirrored (the camera at -x: the body's right side)
    axes = np.diag([-1.0, 1.0, 1.0]) if view.startswith("right") else None
    named = {"right": "side", "right three-quarter": "three-quarter"}.get(view, view)
    camera = named_view(named, lo, hi, aspect=SIZE[0] / SIZE[1], axes=axes)
    out = []
    for volume, origin in shown:
        r = Renderer(RenderSettings(camera, style="surface", preset="bone", size=SIZE, background="#1e1f24"))
        try:
            out.append(r.render(volume, origin))
        finally:
            r.close()
    return out


def main() -> None:
    from skimage import io as skio

    from volanim_core.render.scene import prefer_egl_without_display

    prefer_egl_without_display()
    only = sys.argv[1:]
    for file, (name, bone, rotation, view, joint) in PICTURES.items():
        if only and file not in only:
            continue
        out = HERE / file
        skio.imsave(out, np.concatenate(panels(name, bone, rotation, view, joint), axis=1), check_contrast=False)
        print(f"wrote {out}")


if __name__ == "__main__":
    main()
