"""Marker data -> joint positions in our bones' space, for :func:`volanim_core.motion.positions.solve`.

    .c3d (ezc3d) --io.marker_files.read_c3d--> labels, (F, M, 3) in the lab's units and axes, NaN: marker not seen
    .csv (frame,joint,x,y,z) --io.positions_files.read_positions--> the same
    + a marker map (JOINT MARKER [MARKER ...]) --joints_from_markers--> (F, J, 3): a joint is the mean
      of its markers, missing in a frame where any of them is
    + .bones --fit--> our axes, voxels and place: the data's up and forward axes and its scale

Why a fit: a C3D file is in millimetres in the lab's axes (Qualisys and Vicon put z up, others y), and
our figures stand z up, facing -y, in voxels. The axes are the axis-aligned turn under which the data's
leg, spine and foot directions agree best with ours (as bvh2trans does with a clip's bones); the scale is
our bone lengths over the data's (a median, so a flickering marker cannot set it); the place puts the
first frame's root joint on ours. The solver keeps our lengths, so a scale a few percent off moves the
figure a few percent less or more across the floor, never stretches it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.rig.bones import BoneSkeleton


def default_map(labels: list[str], joints: list[str]) -> dict[str, list[str]]:
    """Markers named after our joints (case aside, and Vicon's ``Subject:`` prefix aside)."""
    by_name = {label.split(":")[-1].upper(): label for label in labels}
    return {j: [by_name[j.upper()]] for j in joints if j.upper() in by_name}


def listed(labels: list[str], most: int = 60) -> str:
    """``"54 markers: Marker_1, ..."`` for an error message, at most ``most`` names."""
    names = [label or "(no label)" for label in labels[:most]]
    return f"{len(labels)} markers: {', '.join(names)}{' ...' if len(labels) > most else ''}"


def joints_from_markers(labels: list[str], markers: np.ndarray, mapping: dict[str, list[str]],
                        joints: list[str], source="") -> np.ndarray:
    """``(F, J, 3)`` for ``joints``: each the mean of its mapped markers, NaN where one is missing.
    A joint the bones lack or a marker the data lacks is refused, naming ``source``."""
    index = {label: m for m, label in enumerate(labels)}
    unknown_joints = sorted(set(mapping) - set(joints))
    if unknown_joints:
        raise ValueError(f"{source}: the bones have no joint {', '.join(unknown_joints)} (theirs: {', '.join(joints)})")
    unknown = sorted({m for ms in mapping.values() for m in ms if m not in index})
    if unknown:
        raise ValueError(f"{source}: no marker {', '.join(unknown)} in the data (its {listed(labels)})")
    out = np.full((len(markers), len(joints), 3), np.nan)
    for j, name in enumerate(joints):
        if name in mapping:
            out[:, j] = markers[:, [index[m] for m in mapping[name]]].mean(axis=1)  # NaN if any is NaN
    return out


@dataclass
class Fit:
    """Data -> ours: ``scale * (A @ p) + shift``, with how each part was decided."""

    up: str
    forward: str
    scale: float
    shift: np.ndarray
    how: str

    def apply(self, positions: np.ndarray) -> np.ndarray:
        return self.scale * positions @ self.axes.T + self.shift

    @property
    def axes(self) -> np.ndarray:
        from volanim_core.motion.retarget import axes_matrix

        return axes_matrix(self.up, self.forward)


def _bone_vectors(bones: BoneSkeleton, positions: np.ndarray, names: list[str]):
    """Per bone with both joints in the data: (bone index, our rest vector, the data's (F, 3) vectors)."""
    index = {n: j for j, n in enumerate(names)}
    for i, b in enumerate(bones.bones):
        if b.proximal in index and b.distal in index:
            data = positions[:, index[b.distal]] - positions[:, index[b.proximal]]
            if np.isfinite(data).all(axis=1).any():
                yield i, np.asarray(bones.joints[b.distal], float) - bones.joints[b.proximal], data


def fit(bones: BoneSkeleton, positions: np.ndarray, names: list[str], up: str = "auto", forward: str = "auto",
        scale: float | None = None) -> Fit:
    """The turn, scale and shift taking ``(F, J, 3)`` data positions (``names`` order) into ``bones``' space."""
    from volanim_core.motion.retarget import ARM_PARTS, _part, axes_matrix

    vectors = list(_bone_vectors(bones, positions, names))
    if not vectors:
        raise ValueError("no bone has both its joints in the data: nothing to fit the axes and scale on")
    how = []
    if "auto" in (up, forward):
        # arms swing and a T-pose differs from arms-down: legs, spine, feet and pelvis tell the axes
        steady = [(ours, data) for i, ours, data in vectors if _part(bones.bones[i].label) not in ARM_PARTS] or \
            [(ours, data) for _, ours, data in vectors]
        ours = np.array([o / np.linalg.norm(o) for o, _ in steady])
        mean = np.array([_mean_direction(d) for _, d in steady])
        names_ = [s + a for a in "xyz" for s in ("", "-")]
        candidates = [(u, f) for u in ([up] if up != "auto" else names_) for f in ([forward] if forward != "auto"
                      else names_) if u.lstrip("+-") != f.lstrip("+-")]
        scores = [float(np.einsum("ij,ij->", ours, mean @ axes_matrix(u, f).T)) for u, f in candidates]
        up, forward = candidates[int(np.argmax(scores))]
        how.append(f"axes from {len(steady)} bones' directions")
    if scale is None:
        ratios = [np.linalg.norm(o) / np.nanmedian(np.linalg.norm(d, axis=1)) for _, o, d in vectors]
        scale = float(np.median(ratios))
        how.append(f"scale from {len(vectors)} bones' lengths")
    a = axes_matrix(up, forward)
    root = next(b.proximal for b, p in zip(bones.bones, bones.parents()) if p is None)
    index = {n: j for j, n in enumerate(names)}
    seen = np.isfinite(positions).all(axis=2)
    if root in index and seen[:, index[root]].any():  # the first frame with the root on ours
        f = int(np.argmax(seen[:, index[root]]))
        shift = np.asarray(bones.joints[root], float) - scale * a @ positions[f, index[root]]
    else:  # else the first frame's mean of what is seen on the same joints' rest mean
        f = int(np.argmax(seen.any(axis=1)))
        cols = [j for j in range(len(names)) if seen[f, j] and names[j] in bones.joints]
        rest = np.mean([bones.joints[names[j]] for j in cols], axis=0)
        shift = rest - scale * a @ positions[f, cols].mean(axis=0)
    return Fit(up, forward, scale, shift, ", ".join(how) or "given")


def _mean_direction(vectors: np.ndarray) -> np.ndarray:
    ok = vectors[np.isfinite(vectors).all(axis=1)]
    units = ok / np.maximum(np.linalg.norm(ok, axis=1, keepdims=True), 1e-12)
    m = units.mean(axis=0)
    return m / max(np.linalg.norm(m), 1e-12)
