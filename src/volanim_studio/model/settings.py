"""View and tool settings: one validated property and one event per setting (Qt-free).

    panel widget --bind (signals blocked on write-back)--> settings.NAME = value
        --validate, store--> settings.events.NAME(value=...) --> scene, panels, controllers

Everything a panel used to keep in its widgets (colour-by, point size, hull,
clipping, slices, preview mode/kernel/padding/joints, lasso and cube tools,
auto-connect options, the current frame) lives here, so the +/- keys and the
cube-size slider, or a saved project and the Display tab, can never disagree.
Settings are not undoable (they are view state), and a project saves them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from volanim_core.modes import MODES
from volanim_core.rig.attach import METHODS

from .events import EventEmitter
from .live_resolution import CHOICES as LIVE_CHOICES
from .selection import DEPTH_MODES


class Mode(StrEnum):
    """The interaction mode (``modes.HANDLERS`` has one handler each); a setting, so a project keeps it."""

    VIEW = "view"
    BONES = "bones"
    ROOT_ORDER = "root_order"
    CUBE = "cube"
    LASSO = "lasso"
    POSE = "pose"


COLOUR_BY = ("thinness", "dt", "bone")
# the core's names, the studio's default first: a preview in bone colours; auto-connect by a path inside
PREVIEW_MODES = ("bone", *(m for m in MODES if m != "bone"))
AUTO_SCOPES = ("unconnected", "all", "selection")
AUTO_METHODS = ("path", *(m for m in METHODS if m != "path"))


def one_of(*choices) -> Callable[[str, Any], Any]:
    def check(name, value):
        if value not in choices:
            raise ValueError(f"{name} must be one of {', '.join(map(str, choices))}, got {value!r}")
        return value
    return check


def number(lo: float, hi: float, kind=float) -> Callable[[str, Any], Any]:
    """A number in ``lo..hi``; with ``kind=int`` a whole one (2.5 is refused, not truncated)."""
    def check(name, value):
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ValueError(f"{name} must be a number, got {value!r}")
        if not lo <= value <= hi:  # also refuses NaN
            raise ValueError(f"{name} must be between {lo:g} and {hi:g}, got {value!r}")
        if kind is int and value != int(value):
            raise ValueError(f"{name} must be a whole number, got {value!r}")
        return kind(value)
    return check


def flag(name, value) -> bool:
    if not isinstance(value, bool) and value not in (0, 1):
        raise ValueError(f"{name} must be true or false, got {value!r}")
    return bool(value)


def axis_or_none(name, value):
    if value is None:
        return None
    return number(0, 2, int)(name, value)


def mode(name, value) -> Mode:
    try:
        return Mode(value)
    except ValueError:
        raise ValueError(f"{name} must be one of {', '.join(Mode)}, got {value!r}") from None


@dataclass(frozen=True)
class Setting:
    default: Any
    check: Callable[[str, Any], Any]
    doc: str
    saved: bool = True  # False: the moment's state (a slider held), never written to a project


SETTINGS: dict[str, Setting] = {
    # display
    "colour_by": Setting("thinness", one_of(*COLOUR_BY), "what colours the skeleton points"),
    "point_size": Setting(6.0, number(1, 30), "skeleton point size, pixels"),
    "spheres": Setting(True, flag, "draw points as shaded spheres"),
    "hull_visible": Setting(True, flag, "show the translucent hull"),
    "names_visible": Setting(True, flag, "joint and bone names in the viewport"),
    "hull_opacity": Setting(0.15, number(0, 1), "hull opacity"),
    "hull_owners": Setting(False, flag, "colour the hull by the bone that owns each surface voxel"),
    "clip_axis": Setting(None, axis_or_none, "axis of the hull's clipping plane (None: no clipping)"),
    "clip_position": Setting(0.5, number(0, 1), "clipping plane position along its axis, 0..1"),
    "slices": Setting(False, flag, "orthogonal slices through the preview"),
    # preview
    "preview_mode": Setting("bone", one_of(*PREVIEW_MODES), "reconstruction mode of the preview"),
    "preview_kernel": Setting(1, one_of(1, 3, 5), "sampled mode's kernel"),
    "preview_padding": Setting(2, number(0, 64, int), "voxels around the posed spheres"),
    "joints": Setting("rigid", one_of("rigid", "smooth"), "how bones meet: rigid, or smooth (blended near joints)"),
    "blend": Setting(1.0, number(0.1, 10), "smooth joints' blend width, times the bones' thickness"),
    "body": Setting("owned", one_of("owned", "spheres"), "how a full preview moves the body: each voxel by the "
                    "bone that owns it (needs the volume), or the thesis's spheres"),
    "live_preview": Setting(True, flag, "a preview while a pose slider moves (half resolution on a large body)"),
    "live_resolution": Setting("auto", one_of(*LIVE_CHOICES), "the live preview's resolution: auto keeps 10 "
                               "pictures a second where it can; full, half or quarter size"),
    "show_rest": Setting(False, flag, "show the rest pose's reconstruction instead (compare)"),
    # connect tools
    "lasso_depth": Setting("visible", one_of(*DEPTH_MODES), "which points under the lasso it takes"),
    "lasso_slab": Setting(10.0, number(0.5, 1000), "slab depth behind the nearest point, voxels"),
    "lasso_remove": Setting(False, flag, "the lasso removes attachments instead of adding"),
    "cube_size": Setting(10.0, number(1, 200), "edge of the connect cube, voxels"),
    "auto_scope": Setting("unconnected", one_of(*AUTO_SCOPES), "which points auto-connect considers"),
    "auto_method": Setting("path", one_of(*AUTO_METHODS), "how auto-connect chooses a bone"),
    "auto_overwrite": Setting(False, flag, "auto-connect may replace existing attachments"),
    # timeline
    "current_frame": Setting(0, number(0, 10**7, int), "the frame shown (motion and sequences)"),
    "follow_body": Setting(True, flag, "the camera follows the body as the timeline plays or steps, and in movies"),
    # interaction
    "mode": Setting(Mode.VIEW, mode, "the interaction mode (View, Bones, Root order, Cube, Lasso, Pose)"),
    "dragging": Setting(False, flag, "a slider is held: the scene draws light, previews wait for the release",
                        saved=False),
    "playing": Setting(False, flag, "the timeline plays: the bones drawn are the drawn body's frame's", saved=False),
}


class Settings:
    """The studio's view and tool settings; ``settings.NAME`` reads, assignment validates and emits."""

    def __init__(self):
        self.events = EventEmitter(*SETTINGS)
        self._values = {name: s.default for name, s in SETTINGS.items()}

    def as_dict(self) -> dict:
        """The settings a project saves (every one but the moment's state, such as a held slider)."""
        return {name: value for name, value in self._values.items() if SETTINGS[name].saved}

    def update(self, values: dict) -> list[str]:
        """Set every known, valid entry of ``values`` (a saved project); returns what was refused."""
        refused = []
        for name, value in values.items():
            try:
                if name not in SETTINGS or not SETTINGS[name].saved:
                    raise ValueError(f"unknown setting {name!r}")
                setattr(self, name, value)
            except ValueError as exc:
                refused.append(str(exc))
        return refused


def _setting_property(name: str) -> property:
    spec = SETTINGS[name]

    def get(self):
        return self._values[name]

    def set_(self, value):
        value = spec.check(name, value)
        if value == self._values[name]:
            return
        self._values[name] = value
        getattr(self.events, name).emit(value=value)

    return property(get, set_, doc=spec.doc)


for _name in SETTINGS:
    setattr(Settings, _name, _setting_property(_name))
