"""The README's colour pictures, rendered off-screen with the library the commands use.

    docs/colour-palettes.png   the colour mannequin: true colour | 255-colour palette unsorted | sorted (ramp)
    docs/colour-posed.png      the colour mannequin with its left arm raised, sampled in colour (kernel 3)

Both are cut open at the body's mid-plane.

Run: make screenshots   (or .venv/bin/python docs/make_colour_renders.py)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
ROOT = HERE.parent
SIZE = (300, 520)


def render(volume, origin, camera, transfer=None) -> np.ndarray:
    """Front half cut away (y < 50, the body's mid-plane), so the inside shows: skin, fat, striped muscle, bone."""
    from volanim_core.render.scene import Renderer, RenderSettings

    cut = ((0.0, 50.0, 0.0), (0.0, -1.0, 0.0))
    r = Renderer(RenderSettings(camera, style="volume", size=SIZE, transfer=transfer, background="#1e1f24", cut=cut))
    try:
        return r.render(volume, origin)
    finally:
        r.close()


def palettes() -> None:
    from skimage import io as skio

    from volanim_core import samples, volume
    from volanim_core.colour.alpha import black_indices, merge_maps
    from volanim_core.colour.palette import NearestColour, build_palette, unique_colours
    from volanim_core.colour.sort import remap_table, sort_palette
    from volanim_core.render.views import named_view

    rgb = samples.mannequin_colour().volume
    camera = named_view("front", (0, 0, 0), np.array(rgb.shape[:3]) - 1)
    palette = build_palette(*unique_colours(rgb), 255)  # k-means: its order is no order
    index = NearestColour(palette)(rgb)
    order = sort_palette(palette, "ramp")
    ramp = volume.remap(index, remap_table(order))

    def tf(p):  # one opacity, black (the background) see-through: `volanim alpha merge P 0.6 --clear-black`
        return merge_maps(p, (np.array([0.0]), np.array([0.6])), black_indices(p))

    pictures = [render(rgb, (0, 0, 0), camera), render(index, (0, 0, 0), camera, tf(palette)),
                render(ramp, (0, 0, 0), camera, tf(palette[order]))]
    out = HERE / "colour-palettes.png"
    skio.imsave(out, np.concatenate(pictures, axis=1), check_contrast=False)
    print(f"wrote {out}")


def posed() -> None:
    from skimage import io as skio

    from volanim_core import io, samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.render.views import named_view
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.pose import pose_matrices, root_bones
    from volanim_core.rig.tskel_tools import connect_to_tskel

    rgb = samples.mannequin_colour().volume
    conn = io.read_connect(ROOT / "assets" / "mannequin.0.50.connect")
    bones = samples.mannequin_bones()
    trans = Trans(root_bones(bones), pose_matrices(bones, {"L_UPPERARM": (0, -60, 0), "R_THIGH": (35, 0, 0)}))
    r = reconstruct(connect_to_tskel(conn, trans), mode="sampled", source=rgb, kernel=3)
    hi = np.array(r.origin) + np.array(r.volume.shape[:3]) - 1
    picture = render(r.volume, r.origin, named_view("three-quarter", r.origin, hi))
    out = HERE / "colour-posed.png"
    skio.imsave(out, picture, check_contrast=False)
    print(f"wrote {out}")


if __name__ == "__main__":
    from volanim_core.render.scene import prefer_egl_without_display

    prefer_egl_without_display()
    palettes()
    posed()
