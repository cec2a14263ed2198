"""Rendering: real off-screen VTK pictures checked against geometry, one camera for every frame,
movies read back with imageio, camera and transfer-function files round-tripped and refused clearly."""

from __future__ import annotations

import json

import imageio.v2 as iio2
import imageio.v3 as iio
import numpy as np
import pytest

from volanim_core import io
from volanim_core.cli import main
from volanim_core.errors import FormatError
from volanim_core.geometry import Geometry
from volanim_core.parallel import RunOn
from volanim_core.render.movie import frame_path, open_inputs, render
from volanim_core.render.scene import Renderer, RenderSettings
from volanim_core.render.views import Camera, named_view
from volanim_core.sequence import store
from volanim_core.transfer_function import TransferFunction

W, H = 320, 240


def ball(shape=(80, 80, 80), centre=(40, 40, 40), radius=20.0, value=1, dtype=np.uint8) -> np.ndarray:
    x, y, z = np.ogrid[: shape[0], : shape[1], : shape[2]]
    d2 = (x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2
    return np.where(d2 <= radius**2, value, 0).astype(dtype)


def lit(image: np.ndarray) -> np.ndarray:
    return image.astype(int).sum(axis=-1) > 40


@pytest.mark.parametrize("style", ["surface", "volume"])
def test_a_sphere_covers_its_projected_disc(style):
    R, D = 20.0, 300.0
    cam = Camera((40.0, 40.0 - D, 40.0), (40.0, 40.0, 40.0), (0.0, 0.0, 1.0), 30.0)
    r = Renderer(RenderSettings(cam, style=style, preset="binary", size=(W, H)))
    try:
        pixels = lit(r.render(ball(radius=R), (0, 0, 0))).sum()
    finally:
        r.close()
    # the silhouette's angular radius is asin(R / D); the picture's half-height is tan(15 degrees)
    expected = np.tan(np.arcsin((R + 0.5) / D)) / np.tan(np.radians(15)) * H / 2  # + half a voxel: its edge
    assert np.sqrt(pixels / np.pi) == pytest.approx(expected, rel=0.04)


@pytest.mark.parametrize("view", ["three-quarter", "front"])
@pytest.mark.parametrize("at", [(230, 20, 10), (0, 540, 300)])
def test_a_body_in_a_corner_of_a_large_sequence_grid_is_drawn_not_clipped(view, at):
    """The clipping range was never reset after the camera was placed: a body in a corner of a long
    walk's shared grid (300 x 600 x 400 voxels) came out black or cut (0 pixels before the fix)."""
    body = np.zeros((60, 60, 60), np.uint8)
    body[10:50, 10:50, 10:50] = 1
    r = Renderer(RenderSettings(named_view(view, (0, 0, 0), (300, 600, 400)), preset="binary", size=(160, 120)))
    try:
        pixels = lit(r.render(body, at)).sum()
    finally:
        r.close()
    # the cube's silhouette seen from ~1000 units: at least 60 pixels in either view
    assert pixels >= 60


def test_a_parallel_camera_draws_true_size_and_the_cut_shows_the_inside():
    shell = ball(radius=20, value=1)
    shell[ball(radius=12) > 0] = 2  # label 2 inside label 1
    cam = Camera((40.0, -500.0, 40.0), (40.0, 40.0, 40.0), (0.0, 0.0, 1.0), 30.0, parallel_scale=40.0)
    whole = Renderer(RenderSettings(cam, preset="bone", size=(W, H)))
    cut = Renderer(RenderSettings(cam, preset="bone", size=(W, H), cut=((40, 40, 40), (0, -1, 0))))
    try:
        a, b = whole.render(shell, (0, 0, 0)), cut.render(shell, (0, 0, 0))
    finally:
        whole.close()
        cut.close()
    radius = np.sqrt(lit(a).sum() / np.pi)
    assert radius == pytest.approx(20.5 / 40.0 * H / 2, rel=0.03)  # R / parallel_scale of the half-height
    from volanim_core.render.volume_style import label_colours

    bone0, bone1 = (np.round(c * 255) for c in label_colours("bone", 2))
    centre = b[H // 2 - 3: H // 2 + 3, W // 2 - 3: W // 2 + 3].reshape(-1, 3).mean(0)
    # the cut face shows label 2's colour in the middle (lit flat on, so its hue, somewhat darker or lighter)
    assert np.argmax(bone1) == np.argmax(centre) and np.argmax(bone0) != np.argmax(centre)
    assert np.argmax(a[H // 2, W // 2]) == np.argmax(bone0)  # uncut: the outer label


def make_sequence(path, frames: int = 4):
    """A tiny OME-Zarr sequence: a static cube in one corner, a ball moving along x."""
    shape = (96, 64, 64)
    store.create(path, shape[::-1], frames, np.uint8, (10, 20, 30), {"key": "test", "mode": "bone",
                 "frames": frames, "numbers": [100 + 2 * i for i in range(frames)]}, fps=12.0)
    arr = store.open_frames(path, "r+")
    for i in range(frames):
        vol = ball(shape, centre=(30 + 12 * i, 32, 32), radius=10, value=2)
        vol[2:10, 2:10, 2:10] = 1
        arr[i] = vol.T
        store.record(path, store.frame_record(i, 100 + 2 * i, vol.T, filled=int((vol > 0).sum())))
    return path


def test_the_camera_stays_fixed_across_frames_and_workers(tmp_path):
    seq = make_sequence(tmp_path / "s.zarr")
    inputs = open_inputs([seq])
    assert inputs.lo == (10, 20, 30) and inputs.hi == (105, 83, 93) and inputs.fps == 12.0
    assert [f.number for f in inputs.frames] == [100, 102, 104, 106]
    cam = named_view("front", inputs.lo, inputs.hi, aspect=W / H)
    rep = render(inputs, RenderSettings(cam, preset="bone", vmax=inputs.vmax, size=(W, H)), tmp_path / "pics",
                 on=RunOn(workers=2))
    assert rep.drawn == 4 and rep.workers == "2 local workers"
    pics = [iio.imread(frame_path(tmp_path / "pics", n)) for n in (100, 102, 104, 106)]
    assert all(p.shape == (H, W, 3) for p in pics)
    static = np.zeros((H, W), bool)  # around the cube: below and left of the ball's path
    static[int(H * 0.62):, : W // 3] = True
    cube = lit(pics[0]) & static
    assert cube.sum() > 50
    for p in pics[1:]:
        assert np.array_equal(p[static], pics[0][static])  # the cube's pixels do not move
    assert not np.array_equal(pics[0], pics[3])  # the ball does


@pytest.mark.long("the one proof that a movie is encoded (imageio-ffmpeg) with its frames, size and rate")
def test_a_movie_has_its_frames_size_and_rate(tmp_path):
    seq = make_sequence(tmp_path / "s.zarr", frames=5)
    assert main(["render", str(seq), "-o", str(tmp_path / "m.mp4"), "--size", "320x240", "--workers", "1"]) == 0
    with iio2.get_reader(tmp_path / "m.mp4", format="FFMPEG") as reader:
        meta, count, first = reader.get_meta_data(), reader.count_frames(), reader.get_data(0)
    assert count == 5 and first.shape == (240, 320, 3) and meta["fps"] == pytest.approx(12.0)
    assert not (tmp_path / ".m.mp4.frames").exists()  # the PNGs are gone once encoded
    assert main(["render", str(seq), "-o", str(tmp_path / "m.gif"), "--size", "200x100", "--fps", "10"]) == 0
    gif = iio.imread(tmp_path / "m.gif", index=None)
    assert gif.shape[:3] == (5, 100, 200)
    assert iio.immeta(tmp_path / "m.gif")["duration"] == pytest.approx(100)  # ms per frame at 10 fps
    assert main(["render", str(seq), "-o", str(tmp_path / "f.gif"), "--size", "64x48", "--fps", "24"]) == 0
    from PIL import Image

    with Image.open(tmp_path / "f.gif") as gif:  # 24 fps in whole centiseconds: 4 and 5 spread, no drift
        delays = []
        for k in range(gif.n_frames):
            gif.seek(k)
            delays.append(gif.info["duration"])
    assert sorted(set(delays)) == [40, 50] and sum(delays) == 210  # 5 frames: 208.3 ms, rounded


def test_a_rerun_draws_only_the_missing_pictures_and_other_settings_redraw(tmp_path, capsys):
    seq = make_sequence(tmp_path / "s.zarr")
    args = ["render", str(seq), "-o", str(tmp_path / "pics"), "--workers", "1", "--size", "160x120"]
    assert main(args) == 0
    first = {n: (tmp_path / "pics" / f"frame.{n:04d}.png").read_bytes() for n in (100, 102, 104, 106)}
    (tmp_path / "pics" / "frame.0102.png").unlink()
    assert main(args) == 0 and "1 drawn, 3 already there" in capsys.readouterr().out
    assert (tmp_path / "pics" / "frame.0102.png").read_bytes() == first[102]
    assert main([*args, "--view", "side"]) == 0 and "4 drawn, 0 already there" in capsys.readouterr().out
    assert json.loads((tmp_path / "pics" / "volanim-render.json").read_text())["frames"] == 4


# spec: docs/formats.md#tf
@pytest.mark.long("a render from a file with a .tf and a saved camera, compared with the voxels")
def test_one_volume_file_to_a_png_with_a_transfer_function_and_a_saved_camera(tmp_path, capsys):
    io.write_volume(tmp_path / "b.vti", ball(radius=15, value=200), Geometry(origin=(5, 5, 5)))
    tf = TransferFunction([0, 100, 255], [[0, 0, 0, 0], [1, 0, 0, 0.2], [1, 0, 0, 1]])
    io.write_transfer_function(tmp_path / "red.tf", tf)
    args = ["render", str(tmp_path / "b.vti"), "-o", str(tmp_path / "b.png"), "--style", "volume", "--tf",
            str(tmp_path / "red.tf"), "--view", "top", "--save-camera", str(tmp_path / "top.camera")]
    assert main(args) == 0
    img = iio.imread(tmp_path / "b.png")
    red = img[lit(img)]
    assert len(red) > 100 and np.all(red[:, 0] >= red[:, 1]) and red[:, 0].mean() > 3 * red[:, 1].mean() + 10
    cam = io.read_camera(tmp_path / "top.camera")
    # the body, not the grid: the ball's filled voxels 25..55 on each axis, at origin 5
    want = named_view("top", (30, 30, 30), (60, 60, 60), aspect=640 / 480)
    assert all(np.allclose(getattr(cam, k), getattr(want, k)) for k in ("position", "focal_point", "view_up"))
    assert main(["render", str(tmp_path / "b.vti"), "-o", str(tmp_path / "c.png"), "--style", "volume", "--tf",
                 str(tmp_path / "red.tf"), "--camera", str(tmp_path / "top.camera")]) == 0
    assert np.array_equal(iio.imread(tmp_path / "c.png"), img)  # the saved camera is the same picture


def test_presets_hold_for_any_value_range():
    from volanim_core.render.scene import preset_transfer

    for vmax in (0.0, 1.0, 2.0, 3.0, 255.0, 1e5):  # a 0/1 volume, a hotspot of 2, a float volume
        for preset in ("sampled", "hotspot"):
            tf = preset_transfer(preset, vmax)
            assert np.all(np.diff(tf.values) > 0) and tf(max(vmax, 1.0))[3] > 0.5


# spec: docs/formats.md#camera
def test_camera_and_transfer_function_files_round_trip(tmp_path):
    cam = Camera((1.5, -2.25, 3e2), (0.1, 0.2, 0.3), (0.0, 0.0, 1.0), 25.0, parallel_scale=40.5)
    io.write_camera(tmp_path / "a.camera", cam)
    assert io.read_camera(tmp_path / "a.camera") == cam
    tf = TransferFunction([-1.5, 0.1, 7e3], [[0.1, 0.2, 0.3, 0.0], [1 / 3, 2 / 3, 1.0, 0.5], [1, 1, 1, 1]])
    io.write_transfer_function(tmp_path / "a.tf", tf)
    assert io.read_transfer_function(tmp_path / "a.tf") == tf
    assert np.allclose(tf([0.1, 3500.05]), [[1 / 3, 2 / 3, 1.0, 0.5], [0.6666666, 0.8333333, 1.0, 0.75]])


# spec: docs/formats.md#camera
@pytest.mark.parametrize("text, line, match", [
    ("position 1 2\nfocal_point 0 0 0\n", 1, "position takes 3 numbers, got 2"),
    ("position 0 -9 0\nfocal_point 0 0 0\nzoom 3\n", 3, "unknown camera key 'zoom'"),
    ("position 0 -9 0\nposition 0 -9 0\n", 2, "position is given twice"),
    ("# volanim camera 1\nposition 0 -9 x\nfocal_point 0 0 0\n", 2, "expected a finite number for position"),
    ("position 0 -9 0\n", None, "a camera needs focal_point"),
    ("position 0 0 0\nfocal_point 0 0 0\n", None, "the same point"),
    ("position 0 -9 0\nfocal_point 0 0 0\nview_up 0 1 0\n", None, "view_up must not"),
    ("position 0 -9 0\nfocal_point 0 0 0\nview_angle 180\n", None, "view_angle must be between"),
])
def test_bad_camera_files_name_the_line(tmp_path, text, line, match):
    (tmp_path / "bad.camera").write_text(text)
    with pytest.raises(FormatError, match=match) as exc:
        io.read_camera(tmp_path / "bad.camera")
    assert exc.value.line == line and "bad.camera" in str(exc.value)


# spec: docs/formats.md#tf
@pytest.mark.parametrize("text, line, match", [
    ("0 0 0 0 0\n10 1 1 1\n", 2, "5 numbers"),
    ("0 0 0 0 0\n10 1 1 1 1\n5 1 1 1 1\n", 3, "values must ascend: 5 follows 10"),
    ("0 0 0 0 0\n10 255 1 1 1\n", 2, "red is between 0 and 1, got 255"),
    ("0 0 0 0 nan\n", 1, "finite number for alpha"),
    ("# only a comment\n", None, "empty"),
])
def test_bad_transfer_function_files_name_the_line(tmp_path, text, line, match):
    (tmp_path / "bad.tf").write_text(text)
    with pytest.raises(FormatError, match=match) as exc:
        io.read_transfer_function(tmp_path / "bad.tf")
    assert exc.value.line == line


def test_render_refusals(tmp_path, capsys):
    seq = make_sequence(tmp_path / "s.zarr")
    for args, match in ((["-o", str(tmp_path / "m.mp4"), "--size", "330x240"], "multiples of 16"),
                        (["-o", str(tmp_path / "one.png")], "4 frames do not fit in one .png")):
        assert main(["render", str(seq), *args]) == 2
        assert match in capsys.readouterr().err
    for bad, match in ((["-o", str(tmp_path / "m.avi")], "render to a .png, .mp4, .gif or a folder"),
                       (["-o", str(tmp_path / "c"), "--cut", "1", "1", "1", "0", "0", "0"], "must not be 0 0 0")):
        with pytest.raises(SystemExit):
            main(["render", str(seq), *bad])
        assert match in capsys.readouterr().err
    (tmp_path / "c.camera").write_text("position 1 2 3\n")
    assert main(["render", str(seq), "-o", str(tmp_path / "x"), "--camera", str(tmp_path / "c.camera")]) == 2
    assert "c.camera: a camera needs focal_point" in capsys.readouterr().err
    assert not (tmp_path / "x").exists() and not (tmp_path / "m.mp4").exists()
    (tmp_path / "notes").mkdir()
    assert main(["render", str(tmp_path / "notes"), "-o", str(tmp_path / "y")]) == 2
    for bad in (["--size", "640"], ["--background", "notacolour"], ["--style", "wire"]):
        with pytest.raises(SystemExit):
            main(["render", str(seq), "-o", str(tmp_path / "z"), *bad])
        assert f"argument {bad[0]}" in capsys.readouterr().err


@pytest.mark.long("the one proof that a real Dask cluster (loopback) renders the frames a local render makes")
def test_a_dask_cluster_draws_the_same_pictures(tmp_path):
    from distributed import Client, LocalCluster

    seq = make_sequence(tmp_path / "s.zarr", frames=3)
    inputs = open_inputs([seq])
    settings = RenderSettings(named_view("side", inputs.lo, inputs.hi), preset="bone", size=(160, 120))
    render(inputs, settings, tmp_path / "local", on=RunOn(workers=1))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address="127.0.0.1:0") as cluster, Client(cluster) as client:
        rep = render(inputs, settings, tmp_path / "dask", on=RunOn(scheduler=client))
    assert rep.workers == "Dask, 2 workers" and rep.drawn == 3
    for n in (100, 102, 104):
        a, b = (iio.imread(frame_path(tmp_path / where, n)) for where in ("dask", "local"))
        assert np.array_equal(a, b)


@pytest.mark.parametrize("style", ["surface", "volume"])
def test_a_reused_plotter_draws_each_frame_as_a_fresh_one_would(style):
    cam = named_view("front", (0, 0, 0), (79, 79, 79), aspect=W / H)
    settings = RenderSettings(cam, style=style, preset="bone", size=(W, H))
    a, b = ball(centre=(25, 40, 40), radius=12, value=1), ball(centre=(55, 40, 40), radius=12, value=2)
    reused, fresh = Renderer(settings), Renderer(settings)
    try:
        reused.render(a, (0, 0, 0))
        second = reused.render(b, (0, 0, 0))
        assert np.array_equal(second, fresh.render(b, (0, 0, 0)))
        assert lit(second)[:, W // 2 + 10:].sum() > 100 and lit(second)[:, : W // 2 - 10].sum() == 0
    finally:
        reused.close()
        fresh.close()


def test_auto_mapper_is_resolved_once_for_the_whole_sequence(tmp_path):
    from volanim_core.render.movie import choose_mapper

    seq = make_sequence(tmp_path / "s.zarr", frames=4)
    inputs = open_inputs([seq])
    settings = RenderSettings(named_view("front", inputs.lo, inputs.hi), style="volume", preset="bone",
                              size=(160, 120))
    chosen = choose_mapper(inputs, settings)
    assert chosen.mapper in ("gpu", "cpu") and chosen.style == "volume"
    rep = render(inputs, settings, tmp_path / "pics", on=RunOn(workers=2))
    assert rep.mapper in ("gpu", "cpu") and rep.drawn == 4
    surface = RenderSettings(settings.camera, preset="bone")
    assert choose_mapper(inputs, surface) is surface  # nothing to choose


def test_hotspot_gets_a_heat_colour_bar_and_labels_do_not():
    counts = ball(radius=15, value=1)
    counts[ball(radius=8) > 0] = 6  # hot in the middle
    cam = named_view("front", (0, 0, 0), (79, 79, 79), aspect=W / H)
    pictures = {}
    for preset in ("hotspot", "bone"):
        r = Renderer(RenderSettings(cam, preset=preset, vmax=6, size=(W, H)))
        try:
            pictures[preset] = r.render(counts, (0, 0, 0)).astype(int)
        finally:
            r.close()
    bar = pictures["hotspot"][H // 5: 3 * H // 5, int(W * 0.89): int(W * 0.91)]
    assert (bar[..., 0] > 200).mean() > 0.5 and bar[..., 2].mean() < bar[..., 0].mean()  # warm colours
    assert not lit(pictures["bone"][:, int(W * 0.89):].astype(np.uint8)).any()  # no bar for labels



@pytest.mark.parametrize("renderer, software", [
    ("llvmpipe (LLVM 15.0.6, 256 bits)", True),
    ("softpipe", True),
    ("Software Rasterizer", True),
    ("NVIDIA GeForce RTX 3060/PCIe/SSE2", False),
    ("Mesa Intel(R) UHD Graphics 620 (KBL GT2)", False),
    ("AMD Radeon Pro 5500M OpenGL Engine", False),
])
def test_software_gl_reads_the_renderer_string(renderer, software):
    from volanim_core.render.volume_style import software_gl

    assert software_gl(renderer) is software


def test_the_renderer_string_comes_from_a_drawn_window():
    import pyvista as pv

    from volanim_core.render.volume_style import gl_renderer

    p = pv.Plotter(off_screen=True, window_size=(64, 64))
    try:
        assert gl_renderer(p.ren_win) == ""  # no context before the first picture
        p.add_mesh(pv.Sphere())
        p.show(auto_close=False)
        report = p.ren_win.ReportCapabilities()
        line = next(x for x in report.splitlines() if "renderer string" in x.lower())
        assert gl_renderer(p.ren_win) == line.split(":", 1)[1].strip() != ""
    finally:
        p.close()
