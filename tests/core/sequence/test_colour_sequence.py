"""A colour body's sequence and movie are in colour (#61 item 7): the frames hold palette indices, the
store holds the palette, and every reader (render, view) draws the colours the studio's preview shows."""

from __future__ import annotations

import json

import imageio.v3 as iio
import numpy as np
import pytest

from paths import ASSETS, WALK
from volanim_core import io, samples
from volanim_core.cli import main
from volanim_core.colour.indexed import index_colours
from volanim_core.colour.space import delta_e
from volanim_core.errors import FormatError
from volanim_core.parallel import RunOn
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.render.movie import open_inputs, read_frame, render
from volanim_core.render.scene import Renderer, RenderSettings
from volanim_core.render.views import named_view
from volanim_core.samples import mannequin_bones
from volanim_core.sequence.checked import read_store
from volanim_core.sequence.frames import frames_from_files
from volanim_core.sequence.run import SequenceSettings, run_sequence, shared_bounds

W, H = 240, 180


@pytest.fixture(scope="module")
def conn():
    return io.read_connect(ASSETS / "mannequin.0.50.connect")


@pytest.fixture(scope="module")
def walk(conn):
    return frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 40, 20))


@pytest.fixture(scope="module")
def rgb():
    return samples.mannequin_colour().volume


def placed(volume, origin, bounds):
    """A single-frame reconstruction put in the sequence's shared grid."""
    out = np.zeros((*bounds.shape, *volume.shape[3:]), volume.dtype)
    at = np.subtract(origin, bounds.lo)
    out[at[0]:at[0] + volume.shape[0], at[1]:at[1] + volume.shape[1], at[2]:at[2] + volume.shape[2]] = volume
    return out


def test_few_colours_are_indexed_exactly_and_many_within_a_just_noticeable_difference(rgb):
    ix = index_colours(rgb)  # 71,422 distinct colours: quantised to 255
    assert not ix.exact and ix.colours == 255 and ix.indices.dtype == np.uint8
    body = rgb.any(axis=3)
    assert np.array_equal(ix.indices > 0, body)  # black (and only black) is the background's 0
    mean, p95 = ix.error
    assert mean < 1.5 and p95 < 3.0  # CIEDE2000; measured 0.82 and 1.62
    # every voxel's colour is checked here independently of the palette's own error sums
    errors = delta_e(rgb[body][::37], ix.colour(ix.indices)[body][::37])
    assert abs(float(errors.mean()) - mean) < 0.1

    few = ix.colour(ix.indices)  # now at most 255 colours besides black: indexed voxel for voxel
    again = index_colours(few)
    assert again.exact and np.array_equal(again.colour(again.indices), few)
    assert again.error == (0.0, 0.0)


def test_each_colour_frame_is_the_colour_preview_placed_in_the_shared_grid(tmp_path, conn, walk, rgb):
    """The studio previews ``reconstruct(sampled, source=rgb)``; the movie's frames must be those colours.
    With at most 255 colours they are exactly those voxels; with more, within the palette's error."""
    few = index_colours(rgb)
    few_rgb = few.colour(few.indices)
    bounds = shared_bounds(conn, walk, 2)
    rep = run_sequence(conn, walk, tmp_path / "few.zarr", SequenceSettings(mode="sampled", source=few_rgb))
    assert rep.colours == "colour: 255 palette colours, exact"
    seq = read_store(tmp_path / "few.zarr")
    assert seq.palette.shape == (256, 3) and seq.dtype == np.uint8
    for i, spec in enumerate(walk):
        alone = reconstruct(spec.tskel(conn), mode="sampled", source=few_rgb)
        assert np.array_equal(seq.read_colour(i), placed(alone.volume, alone.origin, bounds)), f"frame {i}"

    rep = run_sequence(conn, walk, tmp_path / "many.zarr", SequenceSettings(mode="sampled", source=rgb))
    assert rep.colours.startswith("colour: 255 palette colours, quantised (CIEDE2000 mean 0.8")
    seq = read_store(tmp_path / "many.zarr")
    alone = reconstruct(walk[1].tskel(conn), mode="sampled", source=rgb)
    want = placed(alone.volume, alone.origin, bounds)
    got = seq.read_colour(1)
    body = want.any(axis=3)
    assert np.array_equal(got.any(axis=3), body)  # the same voxels filled
    assert float(delta_e(want[body], got[body]).mean()) < 1.5


def test_the_movie_of_a_colour_sequence_is_the_preview_s_colours(tmp_path, conn, walk, rgb):
    few = index_colours(rgb)
    few_rgb = few.colour(few.indices)
    run_sequence(conn, walk[:1], tmp_path / "s.zarr", SequenceSettings(mode="sampled", source=few_rgb))
    inputs = open_inputs([tmp_path / "s.zarr"])
    camera = named_view("front", inputs.lo, inputs.hi, aspect=W / H)
    settings = RenderSettings(camera, preset="sampled", size=(W, H))
    render(inputs, settings, tmp_path / "pics", on=RunOn(workers=1))
    movie = iio.imread(next((tmp_path / "pics").glob("*.png")))
    bounds = shared_bounds(conn, walk[:1], 2)
    alone = reconstruct(walk[0].tskel(conn), mode="sampled", source=few_rgb)
    renderer = Renderer(settings)
    try:  # the preview's colour volume, drawn by the same renderer: the same picture
        preview = renderer.render(placed(alone.volume, alone.origin, bounds), bounds.lo, walk[0].number)
    finally:
        renderer.close()
    assert np.array_equal(movie, preview)
    body = movie.max(axis=2) > 30
    warm = movie[..., 0].astype(int) - movie[..., 2] > 40  # skin: red well above blue; grey has neither
    assert body.sum() > 2000 and (warm & body).sum() > 0.5 * body.sum()
    # with a transfer function of the user's (over the palette's indices), the frame is read as indices
    volume, _ = read_frame(inputs.frames[0], colour=False)
    assert volume.ndim == 3 and volume.max() <= few.colours


def test_the_command_line_sequences_a_colour_scan_and_refuses_averaged_indices(tmp_path, capsys, rgb):
    vol = tmp_path / "mannequin-colour.VOL"
    io.write_volume(vol, rgb)
    trans = tmp_path / "t"
    assert main(["bvh2trans", str(WALK), "--bones", str(ASSETS / "mannequin.bones"), "--frames", "0:2",
                 "-o", str(trans)]) == 0
    args = ["sequence", str(ASSETS / "mannequin.0.50.connect"), *map(str, sorted(trans.glob("*.trans"))),
            "--source", str(vol), "--mode", "sampled", "--workers", "1", "-o", str(tmp_path / "c.zarr")]
    capsys.readouterr()
    assert main(args + ["--kernel", "3"]) != 0
    assert "indices cannot be averaged, got kernel 3" in capsys.readouterr().err
    assert main(args) == 0
    assert "colour: 255 palette colours, quantised" in capsys.readouterr().out
    assert main(["render", str(tmp_path / "c.zarr"), "-o", str(tmp_path / "c.png"), "--frames", "0:1",
                 "--size", "160x120", "--workers", "1"]) == 0
    pic = iio.imread(tmp_path / "c.png")
    body = pic.max(axis=2) > 30
    assert (pic[..., 0].astype(int) - pic[..., 2] > 40)[body].mean() > 0.5


def test_a_store_whose_palette_is_not_256_colours_is_refused_naming_its_file(tmp_path, conn, walk, rgb):
    run_sequence(conn, walk[:1], tmp_path / "s.zarr", SequenceSettings(mode="sampled", source=rgb))
    meta = tmp_path / "s.zarr" / "zarr.json"
    doc = json.loads(meta.read_text())
    doc["attributes"]["volanim"]["palette"] = doc["attributes"]["volanim"]["palette"][:3]
    meta.write_text(json.dumps(doc))
    with pytest.raises(FormatError, match=r"zarr\.json.*\"palette\" must be 256 colours"):
        read_store(tmp_path / "s.zarr")
