"""The user's transfer function (the thesis's Icol): value -> colour and opacity, edited with undo (Qt-free).

    editor (qt/transfer_editor) --add / move / recolour / remove / load / reset--> TransferState.set
        --undo.push(Command)--> _write --> doc.events.transfer(function=...)
            --> the preview (scene/pose_layer), View windows and Render movie draw with it

``function`` is None until the user makes one: then every reconstruction mode keeps its own look (bone
colours, the grey ramp, the heat map). The first edit starts from the look of the mode shown
(:func:`starting_function`), so nothing changes on screen until the user moves something. Edits are pure
functions on :class:`~volanim_core.transfer_function.TransferFunction` (``with_point``, ``moved``,
``recoloured``, ``without``); each is one undo step, a drag of one point one step (merged). The editor shows
one handle per label (:func:`handles`: a label's flat step is two points) and edits both points at once.
A project keeps the function (``document_state``'s ``transfer`` part); ``.tf`` files hold it alone.
"""

from __future__ import annotations

import numpy as np

from volanim_core import io
from volanim_core.errors import FormatError
from volanim_core.render.scene import preset_transfer
from volanim_core.render.volume_style import LABEL_STEP, label_colours, label_steps
from volanim_core.transfer_function import TransferFunction

from .undo import Command

GAP = 1e-6  # the least distance between two points' values (the function's values are strictly ascending)


def starting_function(mode: str, vmax: float, n_bones: int) -> TransferFunction:
    """The look of reconstruction ``mode`` as an editable function: a step of colour per bone (bone),
    one skin step (binary), or the mode's ramp (sampled grey, hotspot heat, mottled over its labels)."""
    if mode in ("bone", "binary"):
        return label_steps(label_colours(mode, n_bones))
    return preset_transfer("hotspot" if mode == "hotspot" else "sampled", vmax)


def with_point(tf: TransferFunction, value: float, opacity: float) -> tuple[TransferFunction, int]:
    """A new point at ``value`` with the colour the function has there and ``opacity``; (function, its index)."""
    value = float(value)
    if np.any(np.abs(tf.values - value) < GAP):
        raise ValueError(f"there is a point at {value:g} already")
    rgba = tf(value).copy()
    rgba[3] = np.clip(opacity, 0, 1)
    i = int(np.searchsorted(tf.values, value))
    return TransferFunction(np.insert(tf.values, i, value), np.insert(tf.rgba, i, rgba, axis=0)), i


def moved(tf: TransferFunction, i: int, value: float, opacity: float) -> TransferFunction:
    """Point ``i`` at ``value`` (kept between its neighbours: points never pass each other) and ``opacity``."""
    lo = tf.values[i - 1] + GAP if i > 0 else -np.inf
    hi = tf.values[i + 1] - GAP if i + 1 < len(tf.values) else np.inf
    values, rgba = tf.values.copy(), tf.rgba.copy()
    values[i] = min(max(float(value), lo), hi)
    rgba[i, 3] = float(np.clip(opacity, 0, 1))
    return TransferFunction(values, rgba)


def recoloured(tf: TransferFunction, i: int, rgb) -> TransferFunction:
    """Point ``i`` in colour ``rgb`` (0..1), its opacity kept."""
    rgba = tf.rgba.copy()
    rgba[i, :3] = np.clip(np.asarray(rgb, np.float64)[:3], 0, 1)
    return TransferFunction(tf.values, rgba)


def without(tf: TransferFunction, i: int) -> TransferFunction:
    """The function without point ``i``; the last point cannot go (a function needs one)."""
    if len(tf.values) == 1:
        raise ValueError("a transfer function keeps at least one point")
    return TransferFunction(np.delete(tf.values, i), np.delete(tf.rgba, i, axis=0))


def handles(tf: TransferFunction) -> list[tuple[int, ...]]:
    """The points a user edits as one, in order: each label's flat step (two points ``2 * LABEL_STEP`` apart
    in one colour, as :func:`~volanim_core.render.volume_style.label_steps` makes them) is one handle; every
    other point is a handle of its own. (#83: in the bone look each bone was two points, and recolouring one
    recoloured half a bone: the arm turned mauve; opacity 0.1 on one left the head solid.)"""
    out, i, n = [], 0, len(tf.values)
    while i < n:
        if (i + 1 < n and abs(tf.values[i + 1] - tf.values[i] - 2 * LABEL_STEP) < 1e-6
                and np.array_equal(tf.rgba[i], tf.rgba[i + 1])):
            out.append((i, i + 1))
            i += 2
        else:
            out.append((i,))
            i += 1
    return out


def handle_value(tf: TransferFunction, handle: tuple[int, ...]) -> float:
    """Where a handle stands: its point's value, or the middle of a label's step (the label's value)."""
    return float(np.mean(tf.values[list(handle)]))


def handle_of(tf: TransferFunction, i: int) -> int:
    """The handle that holds point ``i``."""
    return next(k for k, h in enumerate(handles(tf)) if i in h)


def moved_handle(tf: TransferFunction, handle: tuple[int, ...], value: float, opacity: float) -> TransferFunction:
    """A handle moved to ``value`` and ``opacity``: a step keeps its width and stays between its neighbours."""
    if len(handle) == 1:
        return moved(tf, handle[0], value, opacity)
    a, b = handle
    lo = tf.values[a - 1] + GAP + LABEL_STEP if a > 0 else -np.inf
    hi = tf.values[b + 1] - GAP - LABEL_STEP if b + 1 < len(tf.values) else np.inf
    centre = min(max(float(value), lo), hi)
    values, rgba = tf.values.copy(), tf.rgba.copy()
    values[a], values[b] = centre - LABEL_STEP, centre + LABEL_STEP
    rgba[[a, b], 3] = float(np.clip(opacity, 0, 1))
    return TransferFunction(values, rgba)


def recoloured_handle(tf: TransferFunction, handle: tuple[int, ...], rgb) -> TransferFunction:
    for i in handle:
        tf = recoloured(tf, i, rgb)
    return tf


def without_handle(tf: TransferFunction, handle: tuple[int, ...]) -> TransferFunction:
    if len(handle) == len(tf.values):
        raise ValueError("a transfer function keeps at least one point")
    return TransferFunction(np.delete(tf.values, list(handle)), np.delete(tf.rgba, list(handle), axis=0))


def to_json(tf: TransferFunction | None):
    return None if tf is None else {"values": tf.values.tolist(), "rgba": tf.rgba.tolist()}


def parse(value, path) -> TransferFunction:
    """A project's ``transfer`` part; FormatError naming the project file."""
    try:
        if not isinstance(value, dict) or set(value) != {"values", "rgba"}:
            raise ValueError(f"must be {{\"values\": [...], \"rgba\": [[r, g, b, a], ...]}}, got {value!r:.80}")
        return TransferFunction(np.asarray(value["values"], np.float64), np.asarray(value["rgba"], np.float64))
    except (ValueError, TypeError) as exc:
        raise FormatError(path, f"\"transfer\": {exc}") from None


class TransferState:
    """``doc.transfer``: the user's function (``function``; None: each mode's own look), with undo."""

    def __init__(self, doc):
        self.doc = doc
        self.function: TransferFunction | None = None

    def _write(self, tf: TransferFunction | None) -> None:
        self.function = tf
        self.doc.events.transfer.emit(function=tf)

    def set(self, tf: TransferFunction | None, label: str, merge_key: str | None = None) -> None:
        """Make ``tf`` the function (None: back to each mode's look) as one undo step; ``merge_key`` merges
        consecutive steps (one point dragged)."""
        old = self.function
        if tf is old or (tf is not None and tf == old):
            return
        self.doc.undo.push(Command(label, lambda: self._write(tf), lambda: self._write(old), merge_key))

    def current(self, mode: str, vmax: float) -> TransferFunction:
        """The function to edit: the user's, or the look of ``mode`` (not set until an edit)."""
        return self.function or starting_function(mode, vmax, len(self.doc.bones))

    def load(self, path) -> None:
        """A ``.tf`` file as the function (one undo step); FormatError naming the file and line."""
        self.set(io.read_transfer_function(path), f"Open transfer function {path}")

    def save(self, path, mode: str, vmax: float) -> None:
        io.write_transfer_function(path, self.current(mode, vmax))
