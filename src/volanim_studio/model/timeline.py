"""The animation on the timeline: a loaded clip or pose keys; the current frame drives the pose. Qt-free.

    settings.current_frame --> Timeline.show_frame --> pose.show(matrices) (not an edit: no undo)
    clip:  a clip (BVH, or one animation of a glTF or FBX file) retargeted onto the bones, or a folder of .trans
           frames (takes precedence)
    keys:  frame -> KeyPose, slerped (volanim_core.motion.keyframes); set / delete are undoable
    doc.events.timeline  whenever the clip, the keys, ease or the length change

A clip made from a BVH is retargeted again when the bones change (it keeps
the parsed clip, the mapping and the axes); a clip of ``.trans`` frames
cannot follow an edited skeleton and is unloaded with a message.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from volanim_core.io.bvh_files import Motion
from volanim_core.io.clip_files import read_clip
from volanim_core.io.frame_files import frame_number, read_frames
from volanim_core.motion.keyframes import interpolate
from volanim_core.motion.retarget import Retarget, check_mapping_file
from volanim_core.rig.key_pose import KeyPose

from .undo import Command

DEFAULT_LENGTH, DEFAULT_FPS = 48, 24.0


def check_options(ease, length, fps) -> None:
    """The one rule for the keyed animation's options (the panel and a saved project); ValueError."""
    if not isinstance(ease, bool):
        raise ValueError(f"\"ease\" must be true or false, got {ease!r}")
    if isinstance(length, bool) or not isinstance(length, int) or not 1 <= length <= 100_000:
        raise ValueError(f"\"length\" must be 1 to 100000 frames, got {length!r}")
    if isinstance(fps, bool) or not isinstance(fps, int | float) or not 1 <= fps <= 1000:
        raise ValueError(f"\"fps\" must be 1 to 1000 frames per second, got {fps!r}")


@dataclass
class Clip:
    name: str
    matrices: np.ndarray  # (F, B, 4, 4)
    fps: float
    path: str  # the clip (.bvh, .glb, ...), or the folder of .trans
    frames: list[int] = field(default_factory=list)  # frame numbers (of the files; BVH: 0..F-1)
    motion: Motion | None = None  # BVH only: kept to retarget again when the bones change
    mapping: dict[str, str] | None = None
    up: str = "auto"
    forward: str = "auto"
    animation: str | None = None  # which of a glTF file's animations (None: a BVH's one)

    @property
    def kind(self) -> str:
        return "bvh" if self.motion is not None else "trans"


def retarget_clip(path, bones, motion: Motion, mapping=None, up: str = "auto", forward: str = "auto"):
    """``(bones, Retarget, matrices)``: ``motion`` (read from ``path``) retargeted onto ``bones`` -- pure
    arrays, so a worker can make it (#83: a project's clip was retargeted on the GUI thread)."""
    if mapping is not None:
        check_mapping_file(path, mapping, bones, motion)
    r = Retarget.build(bones, motion, mapping, up=up, forward=forward)
    if not r.mapping:
        raise ValueError(f"{Path(path).name}: no bone is mapped to a joint of the clip; map them by hand")
    return bones, r, r.matrices()


class Timeline:
    def __init__(self, doc):
        self.doc = doc
        self.clip: Clip | None = None
        self.keys: dict[int, KeyPose] = {}
        self.ease = True
        self.length = DEFAULT_LENGTH  # frames of a keyed animation
        self.fps = DEFAULT_FPS  # of a keyed animation
        self.looks = 0  # counts frames shown (the current frame set): an undo after one shows the frame
        doc.settings.events.current_frame.connect(self._on_frame)
        doc.events.bones.connect(self._on_bones)

    # ------------------------------------------------------------ queries
    @property
    def active(self) -> bool:
        """Is anything animated (a clip or at least one key)?"""
        return self.clip is not None or bool(self.keys)

    @property
    def frame_count(self) -> int:
        if self.clip is not None:
            return len(self.clip.matrices)
        return max(self.length, max(self.keys, default=-1) + 1)

    @property
    def frame_rate(self) -> float:
        return self.clip.fps if self.clip is not None else self.fps

    def matrices(self, frames=None) -> np.ndarray:
        """``(F, B, 4, 4)`` pose matrices of ``frames`` (default: all) from the clip or the keys."""
        frames = np.arange(self.frame_count) if frames is None else np.asarray(frames, np.int64).reshape(-1)
        if self.clip is not None:
            return self.clip.matrices[np.clip(frames, 0, len(self.clip.matrices) - 1)]
        return interpolate(self.doc.bones, self.keys, frames, ease=self.ease)

    def frame_number(self, frame: int) -> int:
        """The number a frame's file gets: the clip's own numbering for a .trans folder."""
        if self.clip is not None and self.clip.frames:
            return self.clip.frames[min(frame, len(self.clip.frames) - 1)]
        return frame

    # -------------------------------------------------------------- frames
    def _on_frame(self, value: int) -> None:
        self.looks += 1
        self.show_frame(value)

    def show_frame(self, frame: int | None = None) -> None:
        """Put the frame's pose on the bones (view state, like scrubbing: no undo step)."""
        if not self.active or not len(self.doc.bones):
            return
        frame = self.doc.settings.current_frame if frame is None else frame
        self.doc.pose.show(self.matrices([min(frame, self.frame_count - 1)])[0])

    def step(self, delta: int) -> int:
        """Move the current frame by ``delta``, wrapping around the animation; returns the new frame."""
        n = max(self.frame_count, 1)
        self.doc.settings.current_frame = (self.doc.settings.current_frame + delta) % n
        return self.doc.settings.current_frame

    # ---------------------------------------------------------------- keys
    def _set_keys(self, keys: dict[int, KeyPose]) -> None:
        self.keys = dict(keys)
        self.doc.events.timeline.emit()
        self.show_frame()

    def _push_keys(self, label: str, keys: dict[int, KeyPose]) -> None:
        """One undo step. Its undo gives back what replaying the session without this edit would show:
        the pose the user keyed, unless a frame was shown since (then that frame of the old keys)."""
        old, new = dict(self.keys), dict(keys)
        pose = self.doc.pose
        old_pose = ({k: v.copy() for k, v in pose.angles.items()}, {k: v.copy() for k, v in pose.shifts.items()})
        looks = self.looks

        def undo():
            self._set_keys(old)  # shows the current frame of the old keys
            if self.looks == looks:
                pose._write(*old_pose)

        self.doc.undo.push(Command(label, lambda: self._set_keys(new), undo))

    def _refuse_with_clip(self) -> None:
        if self.clip is not None:
            raise ValueError(f"the clip {self.clip.name} drives the bones: unload it (Timeline → Unload clip) "
                             "to animate with keys")

    def set_key(self, frame: int | None = None) -> int:
        """Key the current pose at ``frame`` (default: the current frame); undoable."""
        self._refuse_with_clip()
        frame = self.doc.settings.current_frame if frame is None else int(frame)
        pose = self.doc.pose
        key = KeyPose({k: v.copy() for k, v in pose.angles.items()}, {k: v.copy() for k, v in pose.shifts.items()})
        self._push_keys(f"Set key at frame {frame}", {**self.keys, frame: key})
        return frame

    def delete_key(self, frame: int | None = None) -> None:
        frame = self.doc.settings.current_frame if frame is None else int(frame)
        if frame not in self.keys:
            raise ValueError(f"there is no key at frame {frame}")
        self._push_keys(f"Delete key at frame {frame}", {f: k for f, k in self.keys.items() if f != frame})

    def set_options(self, *, ease: bool | None = None, length: int | None = None, fps: float | None = None) -> None:
        """Ease in/out, the keyed animation's length in frames and its frame rate (view options: no undo)."""
        ease = self.ease if ease is None else ease
        length = self.length if length is None else length
        fps = self.fps if fps is None else fps
        check_options(ease, length, fps)
        self.ease, self.length, self.fps = ease, length, float(fps)
        self.doc.events.timeline.emit()
        self.show_frame()

    # ---------------------------------------------------------------- clips
    def load_bvh(self, path, mapping: dict[str, str] | None = None, up: str = "auto", forward: str = "auto",
                 motion: Motion | None = None, built=None, animation: str | None = None) -> Retarget:
        """Retarget a clip (BVH, or ``animation`` of a glTF or FBX file: None the first) onto the bones and put it on
        the timeline (FormatError names the file). A load, not an edit: the history starts after it.
        ``built``: see :meth:`_retarget`."""
        return self.doc.loading(lambda: self._retarget(path, mapping, up, forward, motion, built, animation))

    def _retarget(self, path, mapping, up, forward, motion, built=None, animation=None) -> Retarget:
        """:meth:`load_bvh` without touching the history (the bones changed: the clip follows them).
        ``built``: :func:`retarget_clip`'s ``(bones, Retarget, matrices)`` made in a worker, used when
        its bones are the document's."""
        if not len(self.doc.bones):
            raise ValueError("build or open the bone skeleton first: the clip drives its bones")
        if built is None or built[0] != self.doc.bones:
            motion = read_clip(path, animation) if motion is None else motion
            built = retarget_clip(path, self.doc.bones, motion, mapping, up, forward)
        _, r, matrices = built
        motion = r.motion
        used = {self.doc.bones.bones[b].label: motion.names[k] for b, k in r.mapping.items()}
        self._put_clip(Clip(Path(path).stem, matrices, motion.fps, str(path), list(range(motion.frames)),
                            motion, used, r.up, r.forward, motion.animation))
        return r

    def load_trans(self, paths, frames=None) -> Clip:
        """A folder (or list) of ``.trans`` frames of these bones as the clip; a load: the history starts
        after it. ``frames``: what :func:`read_frames` read of ``paths`` already (a reader thread)."""
        return self.doc.loading(lambda: self._take_frames(paths, frames))

    def _take_frames(self, paths, frames=None) -> Clip:
        if not len(self.doc.bones):
            raise ValueError("build or open the bone skeleton first: the frames move its bones")
        mats, files = read_frames(paths, self.doc.bones) if frames is None else frames
        numbers = [frame_number(p) for p in files]
        name = files[0].parent.name if len(files) > 1 else files[0].stem
        clip = Clip(name, mats, self.fps, str(files[0].parent if len(files) > 1 else files[0]),
                    [n if n is not None else i for i, n in enumerate(numbers)])
        self._put_clip(clip)
        return clip

    def _put_clip(self, clip: Clip | None) -> None:
        self.clip = clip
        self.doc.events.timeline.emit()
        st = self.doc.settings
        if st.current_frame >= self.frame_count:
            st.current_frame = 0  # shows that frame
        else:
            self.show_frame()

    def unload(self) -> None:
        self._put_clip(None)

    def _on_bones(self, **_) -> None:
        c = self.clip
        if c is None:
            return
        if c.motion is not None and len(self.doc.bones):
            try:
                self._retarget(c.path, {k: v for k, v in c.mapping.items()
                                        if k in {b.label for b in self.doc.bones.bones}}, c.up, c.forward, c.motion)
                return
            except ValueError as exc:
                self.doc.message(f"The clip {c.name} was unloaded: {exc}")
        else:
            self.doc.message(f"The clip {c.name} was unloaded: its .trans frames were made for the old bones.")
        self._put_clip(None)

    # ------------------------------------------------------------ .keys
    def export_keys(self, path) -> int:
        """Write the keys and their options as a ``.keys`` file (``volanim keys`` makes the same frames)."""
        from volanim_core.io.keys_files import Keys, write_keys

        if not self.keys:
            raise ValueError("no keys to export: set keys on the timeline first (S)")
        write_keys(path, Keys(dict(self.keys), self.fps, self.length, self.ease), self.doc.bones)
        return len(self.keys)

    def import_keys(self, path) -> int:
        """Replace the keys (and the options the file gives) by a ``.keys`` file's; one undo step."""
        from volanim_core.io.keys_files import read_keys

        self._refuse_with_clip()
        k = read_keys(path, self.doc.bones)
        self.set_options(ease=k.ease, length=k.length, fps=k.fps)
        self._push_keys(f"Import {len(k.keys)} keys", k.keys)
        return len(k.keys)

    # ------------------------------------------------------------- project
    def to_json(self) -> dict:
        data = {"keys": {str(f): k.to_json() for f, k in sorted(self.keys.items())}, "ease": self.ease,
                "length": self.length, "fps": self.fps, "clip": None}
        c = self.clip
        if c is not None:
            data["clip"] = {"kind": c.kind, "path": c.path, "mapping": c.mapping, "up": c.up, "forward": c.forward}
            if c.animation is not None:
                data["clip"]["animation"] = c.animation
        return data

    @staticmethod
    def parse(data, where: str) -> dict:
        """A project's ``"timeline"`` checked (ValueError naming ``where``), before anything is applied."""
        if not isinstance(data, dict):
            raise ValueError(f"{where}: \"timeline\" must be an object")
        keys = data.get("keys") or {}
        if not isinstance(keys, dict):
            raise ValueError(f"{where}: \"timeline\": \"keys\" must be an object of frame -> bones")
        parsed = {}
        for f, rows in keys.items():
            if not (isinstance(f, str) and f.isascii() and f.isdigit() and int(f) <= 10**7):
                raise ValueError(f"{where}: a key's frame must be a whole number 0..10000000, got {f!r}")
            parsed[int(f)] = KeyPose.from_json(rows, f"{where}: key at frame {f}")
        ease, length, fps = data.get("ease", True), data.get("length", DEFAULT_LENGTH), data.get("fps", DEFAULT_FPS)
        try:
            check_options(ease, length, fps)
        except ValueError as exc:
            raise ValueError(f"{where}: \"timeline\": {exc}") from None
        clip = data.get("clip")
        if clip is not None:
            mapping = clip.get("mapping") if isinstance(clip, dict) else None
            if (not isinstance(clip, dict) or clip.get("kind") not in ("bvh", "trans")
                    or not isinstance(clip.get("path"), str)
                    or not all(isinstance(clip.get(k, "auto"), str) for k in ("up", "forward", "animation"))
                    or (mapping is not None and not (isinstance(mapping, dict) and all(
                        isinstance(k, str) and isinstance(v, str) for k, v in mapping.items())))):
                raise ValueError(f"{where}: \"timeline\": \"clip\" must be {{\"kind\": \"bvh\" or \"trans\", "
                                 "\"path\": FILE, \"mapping\": {BONE: JOINT}, \"up\": AXIS, \"forward\": AXIS, "
                                 "\"animation\": NAME (glTF)}")
        return {"keys": parsed, "ease": ease, "length": length, "fps": float(fps), "clip": clip}

    def restore(self, parsed: dict, where: str) -> list[str]:
        """Apply :meth:`parse`'s result; a clip that cannot be loaded again is a warning, not a failure."""
        self.ease, self.length, self.fps = parsed["ease"], parsed["length"], parsed["fps"]
        self._set_keys(parsed["keys"])
        clip = parsed["clip"]
        if not clip:
            return []
        read = clip.get("read") or {}  # the file(s) already read in a worker (project.read_project_files)
        try:
            if "error" in read:
                raise ValueError(read["error"])
            if clip["kind"] == "bvh":
                self.load_bvh(clip["path"], clip.get("mapping"), clip.get("up", "auto"), clip.get("forward", "auto"),
                              motion=read.get("motion"), built=read.get("built"), animation=clip.get("animation"))
            else:
                self.load_trans(clip["path"], frames=read.get("frames"))
        except (OSError, ValueError) as exc:
            return [f"{where}: the timeline's clip was not loaded ({exc})"]
        return []
