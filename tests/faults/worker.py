"""Runs reader cases one after another in a process with a memory cap; one JSON line per case.

    python -m tests.faults.worker SPEC.json FIRST_INDEX

The runner restarts it after the case that killed it (a crash) or that did not
finish in time (a hang). The address-space cap turns a header-sized allocation
into a MemoryError (or an abort) instead of eating the machine.
"""

from __future__ import annotations

import json
import resource
import sys
from pathlib import Path

import numpy as np

MEMORY_CAP = 6 << 30  # address space; VTK and numpy need ~1-2 GB of it just to load


def read_sequence(path):
    """Every finished frame of a sequence store, verified (what a movie reads)."""
    from volanim_core.sequence.checked import read_store

    s = read_store(path)
    return [s.read_frame(i) for i in sorted(s.done)]


def api_call(path):
    """The call the file names, given what the files' readers refuse (round3_cases.API)."""
    from volanim_core.camera import Camera
    from volanim_core.colour.palette import build_palette
    from volanim_core.io.frame_files import write_frames
    from volanim_core.render.scene import RenderSettings, prepare_frame
    from volanim_core.rig.bones import Bone, BoneSkeleton
    from volanim_core.rig.connectivity import BoneSegment, Trans
    from volanim_core.samples import mannequin_bones
    from volanim_core.transfer_function import TransferFunction

    name = Path(path).read_text()
    nan = float("nan")
    calls = {
        "write_frames with a NaN matrix": lambda: write_frames(
            Path(path).parent / "out", "f", mannequin_bones(), np.full((1, 18, 4, 4), nan), [0]),
        "a TransferFunction with a NaN value": lambda: TransferFunction([0, nan, 2], np.zeros((3, 4))),
        "a Camera at NaN": lambda: Camera((nan, 0, 0), (0, 0, 0)),
        "build_palette with a negative count": lambda: build_palette(np.zeros((2, 3), np.uint8) + [[0], [9]],
                                                                     [5, -3], 2),
        "a BoneSkeleton with a joint at infinity": lambda: BoneSkeleton(
            {"a": (0, 0, 0), "b": (0, 0, float("inf"))}, [Bone("a", "b")]),
        "a Trans of a NaN matrix": lambda: Trans([BoneSegment((0, 0, 0), (0, 0, 1), "a")], np.full((1, 4, 4), nan)),
        "a 2-channel volume drawn": lambda: prepare_frame(RenderSettings(camera=Camera((0, -9, 0), (0, 0, 0))),
                                                          np.zeros((4, 4, 4, 2), np.uint8), (0, 0, 0)),
    }
    try:
        return calls[name]()
    except ValueError as exc:  # the library's refusal: the case's file names the call
        raise OSError(f"{path}: {exc}") from None


def readers() -> dict:
    from volanim_core import io
    from volanim_core.geometry import IDENTITY
    from volanim_core.io.bvh_files import read_bvh
    from volanim_core.io.clip_files import read_clip
    from volanim_core.io.marker_files import read_c3d
    from volanim_core.io.mesh_files import read_mesh
    from volanim_core.io.palette_files import read_alpha_map, read_palette
    from volanim_core.io.slicer_files import read_markups
    from volanim_studio.model import Document
    from volanim_studio.model.project import apply_project, read_project

    return {"read_volume": io.read_volume, "read_mskel": io.read_mskel, "read_bones": io.read_bones,
            "read_connections": io.read_connections, "read_connect": io.read_connect, "read_trans": io.read_trans,
            "read_tskel": io.read_tskel, "read_project": read_project, "read_bvh": read_bvh, "read_clip": read_clip,
            "read_camera": io.read_camera, "read_transfer_function": io.read_transfer_function,
            "read_mesh": read_mesh, "read_palette": read_palette, "read_alpha_map": read_alpha_map,
            "read_sequence": read_sequence, "read_markups": lambda p: read_markups(p, IDENTITY),
            "read_c3d": read_c3d, "api": api_call,
            "open_project": lambda p: apply_project(Document(), read_project(p), p, reset=True)}


CHECKS = {
    "shape_3_4_5": lambda r: tuple(r.shape) == (3, 4, 5),
    "shape_5_4_3": lambda r: tuple(r.shape) == (5, 4, 3),
    "shape_2_3_4": lambda r: tuple(r.shape) == (2, 3, 4) and r[1, 0, 0] == 1 and r[0, 1, 0] == 2,
    "grey_of_rgb_2_3_4": lambda r: tuple(r.shape) == (2, 3, 4) and r[0, 0, 0] == 1 and r[1, 0, 0] == 4,
    "len_3": lambda r: len(r) == 3,
    "first_pair_A_B": lambda r: r[0] == ("A", "B"),
    "len_3000": lambda r: len(r) == 3000,
    "len_frames_1": lambda r: r.frames == 1 and r.names == ["Hips", "Arm"],
    "warns_dev_zero": lambda r: any("/dev/zero" in w and "not a regular file" in w for w in r),
    "one_cell": lambda r: r.n_cells == 1 and r.n_points >= 3,
    "two_cells": lambda r: r.n_cells == 2 and r.n_points == 4,
    "one_bone": lambda r: len(r.bones) == 1 and set(r.joints) == {"A", "B"},
    "c3d_first_marker_missing": lambda r: np.isnan(r[1][0, 0]).all() and np.isfinite(r[1][0, 1]).all(),
    "c3d_qualisys": lambda r: len(r[0]) == 55 and r[1].shape == (340, 55, 3) and r[2] == 200.0,
    "shape_8_6_4": lambda r: tuple(r.shape) == (8, 6, 4) and int(r.max()) == 300,
    "ct_6000": lambda r: tuple(r.shape) == (6, 5, 2) and r.dtype == np.uint16 and int(r.max()) == 6000,
    "gltf_arm_turned": lambda r: r.names == ["root", "arm", "hand"] and r.frames == 31
    and np.allclose(r.forward_kinematics()[1][-1, 2], [-1, 1, 0], atol=1e-5),
    "two_frames": lambda r: len(r) == 2 and r[0].shape == (6, 5, 4) and int(r[1].max()) == 2,
}


def main() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP, MEMORY_CAP))
    from volanim_core.errors import FormatError

    spec = json.loads(Path(sys.argv[1]).read_text())
    first = int(sys.argv[2])
    table = readers()
    for index in range(first, len(spec)):
        case = spec[index]
        print(json.dumps({"index": index, "started": True}), flush=True)
        result = {"index": index}
        try:
            value = table[case["target"]](case["path"])
            check = case.get("check")
            result.update(outcome="returned", ok=bool(CHECKS[check](value)) if check else True)
        except MemoryError:
            result.update(outcome="memory", message="MemoryError")
        except (FormatError, OSError) as exc:
            result.update(outcome="refused", message=str(exc), type=type(exc).__name__)
        except Exception as exc:  # noqa: BLE001 - the point: any other type is a bug to report
            result.update(outcome="exception", message=f"{type(exc).__name__}: {exc}"[:300])
        print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
