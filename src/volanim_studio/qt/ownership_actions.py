"""The Pose menu's ownership actions: the animator sees whose each rest voxel is, and repaints it.

    Give the cube's voxels to the working bone --> doc.ownership.paint_box (one undo step)
    Show ownership on slices --JobRunner(doc.ownership.of, out_of_reach)--> a SliceWindow tinted by owner;
                                the status line names flesh that comes off when its bone moves
    Hang stray flesh on the limb it rests on --JobRunner(doc.ownership.of, .hang_on)--> doc.ownership.paint_many
                                (one undo step), said by bone

Functions of the :class:`~.preview_controller.PreviewController` that owns the menu (its ``doc``, ``jobs``,
``show_error``, ``attempt``, ``window``, ``viewers``): they talk to the model only.
"""

from __future__ import annotations

import numpy as np


def own_cube(ctl) -> None:
    """The body's voxels inside the cube (Cube mode places it) to the working bone."""
    bone, centre = ctl.doc.working_bone, ctl.doc.cube_centre
    if bone is None or centre is None:
        ctl.show_error("Ownership", "place the cube (Cube mode) and choose the working bone first")
        return
    half = ctl.doc.settings.cube_size / 2
    lo, hi = np.ceil(np.asarray(centre) - half), np.floor(np.asarray(centre) + half)
    ctl.attempt("Ownership", lambda: ctl.doc.ownership.paint_box(lo, hi, bone),
                f"The body inside the cube now moves with {ctl.doc.bones.bones[bone].label} (Ctrl+Z undoes); "
                "preview again (F5).")


def _usable(ctl) -> bool:
    if ctl.doc.settings.body != "owned" or not ctl.doc.ownership.available:
        ctl.show_error("Ownership", "ownership is the body's: open a volume and choose Body: owned")
        return False
    return True


def show_ownership(ctl):
    """The scan's slices, each voxel tinted by the bone that moves it (the ownership with the repaints), in a
    window of its own (``ctl.viewers[-1]``); the mouse says whose each voxel is. Made in a worker: on the
    Visible Human the ownership takes seconds the first time."""
    if not _usable(ctl):
        return None
    conn = ctl.doc.pose.tskel().connectivity
    doc, names = ctl.doc, tuple(b.label for b in ctl.doc.bones.bones)

    def made(progress, cancel):
        from volanim_core.rig.reach import out_of_reach

        own = doc.ownership.of(conn)
        return own, (out_of_reach(own) if own is not None else [])

    def done(result) -> None:
        from volanim_core.render.slices import default_window, describe

        from .slice_window import SlicesSource, SliceWindow

        own, torn = result
        if own is None:
            ctl.show_error("Ownership", "nothing attached: connect points to bones first")
            return
        grey = default_window(doc.volume) if doc.volume.ndim == 3 else None
        source = SlicesSource(doc.volume, doc.spacing, grey, describe(doc.volume, grey),
                              own.volume(doc.mask.shape), names)
        window = SliceWindow(doc.volume_path or "body", source, ctl.window)
        ctl.viewers = [v for v in getattr(ctl, "viewers", []) if v.isVisible()] + [window]
        window.show()
        # flesh that touches the body only through another limb's comes off when its bone moves
        # (rig/reach.py): said here, where the animator can see it and repaint, as volanim connect does
        off = "; ".join(f"{names[k]} {lost:,}" for k, lost in torn)
        doc.message(f"Ownership of {int(own.mask.sum()):,} voxels by {len(names)} bones; the mouse says "
                    "whose a voxel is. Repaint with the cube (Pose menu) or Fix a lump."
                    + (f" Flesh that touches the body only through another limb's, and comes off when its "
                       f"bone moves: {off} voxels (Pose → Hang stray flesh on the limb it rests on)." if off else ""))

    return ctl.jobs.run("Ownership", made, done)


def hang_on(ctl):
    """Flesh that touches the body only through another limb's (and so comes off when its bone moves) given to
    the flesh it hangs from (rig/reach.hang_on; ``volanim connect --hang-on``): one undo step, said by bone."""
    if not _usable(ctl):
        return None
    conn = ctl.doc.pose.tskel().connectivity
    doc, names = ctl.doc, tuple(b.label for b in ctl.doc.bones.bones)
    version = doc.ownership.version

    def made(progress, cancel):
        own = doc.ownership.of(conn)
        return None if own is None else doc.ownership.hang_on(own)

    def done(result) -> None:
        if result is None:
            ctl.show_error("Ownership", "nothing attached: connect points to bones first")
            return
        if doc.ownership.version != version:  # repainted meanwhile: these voxels were found on an older one
            ctl.show_error("Ownership", "the ownership was repainted meanwhile: hang stray flesh on again")
            return
        paints, moved = result
        if not moved:
            doc.message("No flesh hangs on another limb's only: nothing to hang on.")
            return
        said = "; ".join(f"{names[a]} {n:,} voxels to {names[b]}" for a, b, n in moved)
        ctl.attempt("Ownership", lambda: doc.ownership.paint_many(paints, f"Hang stray flesh on: {said}"),
                    f"Flesh that touched the body only through another limb's now moves with it: {said} "
                    "(Ctrl+Z undoes); preview again (F5).")

    return ctl.jobs.run("Ownership", made, done)
