"""BVH clips written for tests where no real clip with a licence we can ship is on hand (an elephant, an
insect): a hierarchy of ``(joint, parent, offset)`` and each frame's channels, as rigging tools write them
(the root: position then ZXY rotation; every other joint: ZXY rotation)."""

from __future__ import annotations


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
