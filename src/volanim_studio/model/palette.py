"""Bone colours: 16 clearly distinct colours (the old tool cycled 12), by root order."""

from __future__ import annotations

# A Glasbey-style set, tuned for a dark 3D background; neighbours differ in hue.
PALETTE = (
    "#e6194b", "#3cb44b", "#ffe119", "#4363d8", "#f58231", "#911eb4", "#42d4f4", "#f032e6",
    "#bfef45", "#fabed4", "#469990", "#dcbeff", "#9a6324", "#fffac8", "#800000", "#aaffc3",
)
UNCONNECTED = "#8c8c8c"


def bone_colour(index: int) -> str:
    return PALETTE[index % len(PALETTE)]


def rgb(hex_colour: str) -> tuple[float, float, float]:
    h = hex_colour.lstrip("#")
    return tuple(int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4))
