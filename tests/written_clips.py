"""BVH (and one glTF) clips written for tests where no real clip with a licence we can ship is on hand (an elephant, an
insect): a hierarchy of ``(joint, parent, offset)`` and each frame's channels, as rigging tools write them
(the root: position then ZXY rotation; every other joint: ZXY rotation)."""

from __future__ import annotations

import base64
import json

import numpy as np


def tiny_gltf(times=(0.0, 1.0), quats=((0, 0, 0, 1), (0, 0, 0.7071068, 0.7071068)), interpolation="LINEAR",
              count=None, **override) -> bytes:
    """A three-joint glTF clip as exporters write one: a root, an arm one unit up and its hand one more, the
    arm turned by the keys (data in a data: URI). ``count`` claims that many keys; ``override`` replaces
    top-level entries (``nodes``, ``buffers``, ``animations``)."""
    t, q = np.asarray(times, np.float32), np.asarray(quats, np.float32)
    data = t.tobytes() + q.tobytes()
    doc = {"asset": {"version": "2.0"},
           "nodes": [{"name": "root", "children": [1]}, {"name": "arm", "translation": [0, 1, 0], "children": [2]},
                     {"name": "hand", "translation": [0, 1, 0]}],
           "buffers": [{"byteLength": len(data),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
           "bufferViews": [{"buffer": 0, "byteLength": t.nbytes},
                           {"buffer": 0, "byteOffset": t.nbytes, "byteLength": q.nbytes}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": count or len(t), "type": "SCALAR"},
                         {"bufferView": 1, "componentType": 5126, "count": count or len(q), "type": "VEC4"}],
           "animations": [{"name": "turn", "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}],
                           "samplers": [{"input": 0, "output": 1, "interpolation": interpolation}]}]}
    doc.update(override)
    return json.dumps(doc).encode()


def write_bvh(path, joints, channels, frames: int, end=(0, -1, 0), frame_time: float = 1 / 30) -> None:
    """``joints``: ``(name, parent, offset)``, the root's parent None; ``channels(frame, name)``: the root's
    six values, or another joint's three (Z, X, Y degrees); an End Site ``end`` under every leaf."""
    kids: dict = {}
    for name, parent, _ in joints:
        kids.setdefault(parent, []).append(name)
    offsets = {name: o for name, _, o in joints}
    order: list[str] = []
    lines = ["HIERARCHY"]

    def write(name, depth):
        pad = "  " * depth
        lines.extend([f"{pad}{'ROOT' if depth == 0 else 'JOINT'} {name}", f"{pad}{{",
                      f"{pad}  OFFSET {' '.join(f'{v:g}' for v in offsets[name])}",
                      f"{pad}  CHANNELS " + ("6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
                                             if depth == 0 else "3 Zrotation Xrotation Yrotation")])
        order.append(name)
        for k in kids.get(name, []):
            write(k, depth + 1)
        if name not in kids:
            lines.extend([f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET {' '.join(f'{v:g}' for v in end)}",
                          f"{pad}  }}"])
        lines.append(f"{pad}}}")

    write(kids[None][0], 0)
    lines += ["MOTION", f"Frames: {frames}", f"Frame Time: {frame_time:.7f}"]
    for f in range(frames):
        lines.append(" ".join(f"{v:.4f}" for name in order for v in channels(f, name)))
    path.write_text("\n".join(lines) + "\n")


# joint, parent, offset (cm, Y up, facing +z): an elephant as 3ds Max's biped rigs one
ELEPHANT = [
    ("Bip01", None, (0, 160, 0)), ("Bip01_Pelvis", "Bip01", (0, 0, 0)), ("Bip01_Spine", "Bip01_Pelvis", (0, 0, 5)),
    *[(f"Bip01_{s}_{n}", p, o) for s, x in (("L", 30), ("R", -30)) for n, p, o in (
        ("Thigh", "Bip01_Spine", (x, -15, -10)), ("Calf", f"Bip01_{s}_Thigh", (0, -55, 0)),
        ("HorseLink", f"Bip01_{s}_Calf", (0, -45, 0)), ("Foot", f"Bip01_{s}_HorseLink", (0, -35, 0)))],
    ("BN_Tail_01", "Bip01_Spine", (0, 0, -40)), ("BN_Tail_02", "BN_Tail_01", (0, -20, -40)),
    ("BN_Tail_03", "BN_Tail_02", (0, -30, -30)),
    ("Bip01_Spine1", "Bip01_Spine", (0, 5, 60)), ("Bip01_Spine2", "Bip01_Spine1", (0, 5, 60)),
    ("Bip01_Neck", "Bip01_Spine2", (0, 10, 30)),
    *[(f"Bip01_{s}_{n}", p, o) for s, x in (("L", 30), ("R", -30)) for n, p, o in (
        ("Clavicle", "Bip01_Neck", (x / 2, -10, 0)), ("UpperArm", f"Bip01_{s}_Clavicle", (x / 2, -20, 0)),
        ("Forearm", f"Bip01_{s}_UpperArm", (0, -60, 0)), ("Hand", f"Bip01_{s}_Forearm", (0, -55, 0)))],
    ("Bip01_Head", "Bip01_Neck", (0, 20, 40)),
]


def elephant_bvh(path, frames: int = 48, side: bool = False) -> None:
    """The elephant trotting (diagonal legs together); ``side``: the whole clip lying on its side."""
    swing = {"Bip01_L_Thigh": 1, "Bip01_R_UpperArm": 1, "Bip01_R_Thigh": -1, "Bip01_L_UpperArm": -1}

    def channels(f, name):
        phase = np.sin(2 * np.pi * f / 24)
        if name == "Bip01":
            return [0, 160, 3.0 * f, 90 if side else 0, 0, 0]
        return [0, 25 * phase * swing.get(name, 0) + (10 * abs(phase) if "Calf" in name else 0), 0]

    write_bvh(path, ELEPHANT, channels, frames, end=(0, -10, 0))


# joint, parent, offset (cm, Y up, facing +z): an insect, six legs from the thorax, as a tripod walks
INSECT = [("Thorax", None, (0, 10, 0)), ("Abdomen", "Thorax", (0, 0, -8)), ("AbdomenTip", "Abdomen", (0, -1, -8)),
          ("Neck", "Thorax", (0, 0, 6)), ("Head", "Neck", (0, 1, 3)),
          *[(f"{s}{part}{i}", f"{s}{parent}{i}" if parent else "Thorax", (sign * o[0], o[1], z if k == 0 else 0))
            for s, sign in (("L", 1), ("R", -1)) for i, z in ((1, 3), (2, 0), (3, -3))
            for k, (part, parent, o) in enumerate((("Coxa", None, (2, 0)), ("Femur", "Coxa", (4, 3)),
                                                   ("Tibia", "Femur", (3, -4)), ("Tarsus", "Tibia", (3, -8))))]]


def insect_bvh(path, frames: int = 48) -> None:
    """Tripod gait: legs L1, R2, L3 swing forward about the vertical while R1, L2, R3 swing back."""
    tripod = {"LCoxa1": 1, "RCoxa2": 1, "LCoxa3": 1, "RCoxa1": -1, "LCoxa2": -1, "RCoxa3": -1}

    def channels(f, name):
        if name == "Thorax":
            return [0, 10, 0.5 * f, 0, 0, 0]
        # about the vertical, forward: the left legs turn with -y, the right ones with +y
        return [0, 0, 20 * np.sin(2 * np.pi * f / 24) * tripod.get(name, 0) * (-1 if name.startswith("L") else 1)]

    write_bvh(path, INSECT, channels, frames)
