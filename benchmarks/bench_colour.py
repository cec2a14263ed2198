"""Colour benchmark: palette orderings scored, palette building, and voxels per second mapped to a palette.

1. Orderings x (sum and max CIEDE2000 between neighbouring indices, midpoint error, seconds) on the colour
   mannequin and on three photographs scikit-image ships (astronaut, coffee, chelsea), each reduced to
   255 colours by k-means. The midpoint error is over the colour pairs that touch in the data (face
   neighbours in the index volume or image), weighted by how often. The baseline to beat is the thesis's
   best, SuperGradientSort after an intensity pre-sort: ratios are each / it (below 1 is better).
   Ours are ``ramp`` (the default) and ``path``.
2. Building the palette: k-means in CIELAB against median cut, time and error on the colour mannequin.
3. Mapping voxels to the palette: one KD-tree query per voxel (the baseline), our table filled on demand
   (first volume, then a second volume of the same scan), InvCMap's complete 2^24 table, and the whole
   streamed command (raw file in, raw file out).

    .venv/bin/python benchmarks/bench_colour.py
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import best_of, table  # noqa: E402

ORDERINGS = ("unsorted", "intensity", "rgb-radix", "cluster-seeds", "gradient-penalty", "supergradient", "lightness",
             "moved", "ramp", "path")


def datasets():
    """name -> (palette as built, index data whose touching pairs score the midpoint error)."""
    from skimage import data

    from volanim_core import samples
    from volanim_core.colour.palette import NearestColour, build_palette, unique_colours

    out = {}
    for name, rgb in (("colour mannequin", samples.mannequin_colour().volume), ("astronaut", data.astronaut()),
                      ("coffee", data.coffee()), ("chelsea", data.chelsea())):
        palette = build_palette(*unique_colours(rgb), 255)
        index = NearestColour(palette)(rgb)
        out[name] = (palette, index if index.ndim == 3 else index[:, :, None])
    return out


def bench_orderings(sets) -> None:
    from volanim_core.colour import sort as S

    S.sort_palette(np.random.default_rng(0).integers(0, 256, (20, 3)).astype(np.uint8), "path")  # compile
    S.sort_palette(np.random.default_rng(0).integers(0, 256, (20, 3)).astype(np.uint8), "cluster-seeds")
    rows, wins = [], {"ramp": [], "path": []}
    for name, (palette, index) in sets.items():
        pairs, weights = S.colour_pairs(index, len(palette))
        scores = {}
        for method in ORDERINGS:
            seconds = best_of(lambda m=method, p=palette: S.sort_palette(p, m), 1 if method == "path" else 3)
            scores[method] = (S.score(palette, S.sort_palette(palette, method), pairs, weights), seconds)
        base = scores["supergradient"][0]
        for method in ORDERINGS:
            s, seconds = scores[method]
            rows.append([name, method + (" (baseline)" if method == "supergradient" else ""), f"{s['sum']:.0f}",
                         f"{s['max']:.1f}", f"{s['midpoint']:.2f}", f"{seconds:.2f}",
                         f"{s['sum'] / base['sum']:.2f}", f"{s['max'] / base['max']:.2f}",
                         f"{s['midpoint'] / base['midpoint']:.2f}"])
        for ours in wins:
            wins[ours].append([scores[ours][0][k] <= base[k] for k in ("sum", "max", "midpoint")])
    print("\nPalette orderings (255 colours; CIEDE2000; ratios: this ordering / SuperGradientSort, below 1 is better)")
    print(table(rows, ["data", "ordering", "sum dE", "max dE", "midpoint dE", "s", "sum ratio", "max ratio",
                       "midpoint ratio"]))
    for ours, won in wins.items():
        won = np.array(won)
        print(f"{ours} at or below SuperGradientSort in {len(won)} datasets: sum {won[:, 0].sum()}, "
              f"max {won[:, 1].sum()}, midpoint {won[:, 2].sum()}")


def bench_build() -> None:
    from volanim_core import samples
    from volanim_core.colour.palette import build_palette, quantisation_error, unique_colours

    colours, counts = unique_colours(samples.mannequin_colour().volume)
    body = colours.any(axis=1)
    rows, base = [], None
    for method in ("median-cut", "kmeans"):
        t0 = time.perf_counter()
        palette = build_palette(colours, counts, 255, method=method)
        seconds = time.perf_counter() - t0
        mean, p95 = quantisation_error(colours[body], counts[body], palette)
        base = base or seconds
        rows.append([method, f"{seconds:.2f}", f"{seconds / base:.1f}", f"{mean:.2f}", f"{p95:.2f}"])
    print(f"\nBuilding 255 colours for the colour mannequin ({int(counts.sum()):,} voxels, {len(colours):,} distinct; "
          "error over the body's voxels)")
    print(table(rows, ["method", "s", "time vs median cut", "mean dE", "95th pct dE"]))


def bench_apply() -> None:
    from volanim_core import io, samples
    from volanim_core.colour.palette import NearestColour, build_palette, unique_colours
    from volanim_core.colour.slabs import ColourSlabs, apply_palette

    rgb = samples.mannequin_colour().volume
    half = rgb[:, :, : rgb.shape[2] // 2]  # the first volume of the scan; the second half is the second
    palette = build_palette(*unique_colours(rgb), 255)
    n = half[..., 0].size
    per_voxel = best_of(lambda: NearestColour(palette).per_voxel(half), 1)
    mapper = NearestColour(palette)
    t0 = time.perf_counter()
    mapper(half)
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    mapper(rgb[:, :, rgb.shape[2] // 2:])
    warm = time.perf_counter() - t0
    full = NearestColour(palette)
    t0 = time.perf_counter()
    full.full_table()
    build_full = time.perf_counter() - t0
    lookup_full = best_of(lambda: full(half))
    with tempfile.TemporaryDirectory() as tmp:
        io.write_volume(Path(tmp) / "scan.VOL", rgb)
        t0 = time.perf_counter()
        apply_palette(ColourSlabs.open(Path(tmp) / "scan.VOL"), palette, Path(tmp) / "index.VOL")
        streamed = time.perf_counter() - t0
    rate = lambda seconds, voxels=n: f"{voxels / seconds / 1e6:.1f}"  # noqa: E731
    rows = [["KD-tree query per voxel (baseline)", rate(per_voxel), "1.0"],
            ["table filled on demand: first volume", rate(cold), f"{per_voxel / cold:.1f}"],
            ["table filled on demand: next volume of the scan", rate(warm), f"{per_voxel / warm:.1f}"],
            ["InvCMap's complete 2^24 table: lookups", rate(lookup_full), f"{per_voxel / lookup_full:.1f}"],
            [f"  (building that table: {build_full:.1f} s, = {build_full / cold:.0f} first volumes)", "", ""],
            ["palette apply, streamed raw file to raw file (whole scan)", rate(streamed, rgb[..., 0].size),
             f"{per_voxel / n * rgb[..., 0].size / streamed:.1f}"]]
    print(f"\nMapping the colour mannequin's voxels to 255 colours ({n:,} voxels a half; M voxels/s)")
    print(table(rows, ["method", "M voxels/s", "vs per voxel"]))


def main() -> None:
    bench_orderings(datasets())
    bench_build()
    bench_apply()


if __name__ == "__main__":
    main()
