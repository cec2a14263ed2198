"""The scene's layers on an off-screen plotter and a Document, no main window (#68; napari tests its _vispy
layers the same way): each layer follows the model's events, and what it draws is checked against the
model, not against itself.

    Document (the mannequin: volume, hull, skeleton, bones, attachments) --events--> SceneView(off-screen Plotter)
        --> the cloud's points (the document's shown points), the bones' tubes, the hull, picking, the pose
"""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from paths import ASSETS
from volanim_core import samples
from volanim_core.rig.pose import pose_matrices, posed_joints
from volanim_core.skeleton.hull import display_hulls
from volanim_core.skeleton.skeletonize import skeletonize
from volanim_studio.model.document import Document
from volanim_studio.scene.view import SceneView

SIZE = (320, 240)


@pytest.fixture(scope="module")
def mannequin():
    s = samples.mannequin()
    return s, skeletonize(s.mask), display_hulls(s.mask)


@pytest.fixture
def scene(mannequin):
    s, skel, ((verts, faces), lod) = mannequin
    doc = Document()
    plotter = pv.Plotter(off_screen=True, window_size=SIZE)
    view = SceneView(plotter, doc)  # first, as the window makes it: the scene learns everything from events
    doc.set_volume(s.volume, s.mask)
    doc.set_hull(verts, faces, lod=lod)
    doc.set_skeleton(skel)
    yield view
    plotter.close()


def test_the_cloud_shows_the_document_s_points_and_follows_the_thinness(scene):
    doc = scene.doc
    shown = doc.shown_indices()
    assert len(shown) == doc.visible_count == scene.shown_points > 1000
    drawn = np.asarray(scene.plotter.actors["cloud"].GetMapper().GetInput().points)
    assert np.allclose(drawn, scene.world(doc.skeleton.points[shown]))  # the document's points, in world units
    before = scene.shown_points
    doc.thinness = doc.thinness_range[0] + 0.8 * (doc.thinness_range[1] - doc.thinness_range[0])  # fewer points
    assert len(doc.shown_indices()) == scene.shown_points < before


def test_the_bones_layer_draws_a_tube_per_bone_and_the_halo_follows_the_selection(scene):
    doc = scene.doc
    assert "bones" not in scene.plotter.actors
    doc.bone_edits.set_bones(samples.mannequin_bones())
    assert "bones" in scene.plotter.actors and "joints" in scene.plotter.actors
    tubes = scene.plotter.actors["bones"].GetMapper().GetInput()
    lo, hi = np.array(tubes.bounds).reshape(3, 2).T
    joints = scene.world(np.array(list(doc.bones.joints.values())))
    assert (joints.min(0) >= lo - 1e-6).all() and (joints.max(0) <= hi + 1e-6).all()  # the tubes span the joints
    doc.select_bones([doc.bones.index("L_UPPERARM")])
    assert scene.plotter.actors["selected"].GetVisibility()


def _display(renderer, world) -> np.ndarray:
    """VTK's own world -> display coordinates (vtkCoordinate), not the scene's projection code."""
    import vtk

    c = vtk.vtkCoordinate()
    c.SetCoordinateSystemToWorld()
    out = []
    for p in world:
        c.SetValue(*map(float, p))
        out.append(c.GetComputedDoubleDisplayValue(renderer))
    return np.array(out)


def test_a_click_picks_the_front_most_point_under_it(scene):
    """Checked with VTK's own projection (vtkCoordinate), not the scene's matrices."""
    from volanim_studio.scene.view import PICK_RADIUS

    scene.front_view()
    scene.plotter.render()
    doc, renderer = scene.doc, scene.plotter.renderer
    shown = doc.shown_indices()
    world = scene.world(doc.skeleton.points[shown])
    xy = _display(renderer, world)
    cam = renderer.GetActiveCamera()
    eye = np.array(cam.GetPosition())
    ahead = np.array(cam.GetDirectionOfProjection())
    depth = (world - eye) @ ahead  # how far along the view: what hides what
    inside = np.flatnonzero((xy[:, 0] > 5) & (xy[:, 0] < SIZE[0] - 5) & (xy[:, 1] > 5) & (xy[:, 1] < SIZE[1] - 5))
    assert len(inside) > 500
    for k in inside[:: max(1, len(inside) // 25)]:
        got = scene.pick(*xy[k]).point
        assert got is not None
        j = int(np.flatnonzero(shown == got)[0])
        assert np.linalg.norm(xy[j] - xy[k]) <= PICK_RADIUS + 1e-6  # under the click
        under = np.linalg.norm(xy - xy[k], axis=1) <= PICK_RADIUS
        assert depth[j] <= depth[under].min() + 1e-6  # the front-most of the points under the click


def test_the_hull_follows_its_settings(scene):
    hull = scene.plotter.actors["hull"]
    assert hull.GetVisibility() and not hull.GetPickable()
    scene.doc.settings.hull_opacity = 0.5
    assert hull.GetProperty().GetOpacity() == pytest.approx(0.5)
    scene.doc.settings.hull_visible = False
    assert not hull.GetVisibility()


def test_posing_draws_the_posed_bones_where_the_pose_puts_the_joints(scene):
    doc = scene.doc
    doc.bone_edits.set_bones(samples.mannequin_bones())
    doc.attachments.load(ASSETS / "mannequin.0.50.connect")
    scene.set_posing(True)
    doc.pose.set_angles(doc.bones.index("L_UPPERARM"), (0.0, 0.0, 80.0))
    want = posed_joints(doc.bones, pose_matrices(doc.bones, {"L_UPPERARM": (0.0, 0.0, 80.0)}))
    lines = np.asarray(pv.wrap(scene.xray.actors["posed_bones"].GetMapper().GetInput()).points)
    for name in ("L_ELBOW", "L_WRIST", "R_ELBOW"):  # the moved arm's joints, and one the pose left alone
        assert np.linalg.norm(lines - scene.world(want[name][None]), axis=1).min() < 1.0, name
    assert np.linalg.norm(scene.world(want["L_WRIST"][None]) - scene.world(
        np.array([doc.bones.joints["L_WRIST"]])), axis=1)[0] > 20  # (the wrist did move)


def test_the_hull_is_drawn_as_vtk_s_smooth_shading_drew_it(scene, mannequin):
    """The hull's normals come with the document (made by the volume's worker); the picture is the one
    pyvista's ``smooth_shading=True`` drew from normals it made on the GUI thread."""
    from volanim_studio.scene.hull_layer import HULL_COLOUR

    scene.doc.settings.hull_opacity = 1.0
    for name in ("cloud", "bones", "joints", "selected"):
        if name in scene.plotter.actors:
            scene.plotter.actors[name].SetVisibility(False)
    scene.plotter.view_xz()
    ours = scene.plotter.screenshot(return_img=True).astype(int)
    verts, faces = mannequin[2][0]
    cells = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
    scene.plotter.actors["hull"].SetVisibility(False)  # the same window, lights and camera; pyvista's own way
    scene.plotter.add_mesh(pv.PolyData(scene.world(verts).astype(np.float32), cells), color=HULL_COLOUR,
                           smooth_shading=True, name="theirs", reset_camera=False)
    want = scene.plotter.screenshot(return_img=True).astype(int)
    body = (want != want[0, 0]).any(axis=2)
    assert body.mean() > 0.05  # (the body is in the picture)
    assert np.abs(ours - want).max() <= 2, np.abs(ours - want).max()  # (area-weighted normals: 18)
