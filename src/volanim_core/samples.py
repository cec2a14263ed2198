"""Demo data: a procedural mannequin, the thesis's aliascube, and the real frog.

    mannequin()  (160, 100, 300) uint8  layered humanoid + BoneSkeleton + part labels
    mannequin_colour()  (160, 100, 300, 3) uint8  the same body in anatomical colours (RGB)
    mannequin_large()  (290, 169, 940) uint8  the same body at half-size Visible Human scale
    mannequin_full()  (580, 338, 1880) uint8  the same body on the full Visible Human grid (368 M voxels)
    aliascube()  (128, 128, 128) uint8  107^3 checkerboard of 50 / 250 (thesis Table 5.2)
    frog()       (500, 470, 136) uint8  tissue labels from pyvista's wheel (offline),
                                         with a two-bone principal-axis chain
    curved_tube()  (99, 19, 59) uint8  a tube bent through half a circle, 8 chained bones (the colon case)
    walk_clip()  the real motion-capture walk (BVH, 1064 frames, MIT licence beside it)

The mannequin faces -y with z up, so its left side (``L_`` bones) is at +x;
it is mirror-symmetric about the volume's mid-plane x = 79.5.
Each body part is a tapered capsule around one bone; a voxel belongs to the
part in which it lies deepest, which also gives the ground-truth bone of every
voxel (``part``), used to score automatic connectivity.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.mannequin_body import (  # noqa: F401 -- the body's names are the samples' too
    BONE,
    BRAIN,
    FAT,
    FULL_SHAPE,
    LARGE_SHAPE,
    MANNEQUIN_SHAPE,
    MID_X,
    MUSCLE_A,
    MUSCLE_B,
    SKIN,
    SKULL,
    mannequin_bones,
    mannequin_bones_at,
    paint_mannequin,
)
from volanim_core.progress import stage
from volanim_core.rig.bones import Bone, BoneSkeleton

NAMES = ("mannequin", "mannequin-colour", "mannequin-large", "aliascube", "frog", "curved-tube")
#: Samples that are files rather than volumes: ``volanim samples walk`` copies the clip and its licence;
#: ``mannequin-ct`` writes the mannequin as a CT scan arrives, a DICOM series (:func:`write_mannequin_ct`);
#: ``ant`` copies the closed ant mesh pyvista's wheel ships (``ant.ply``), a model to voxelize, with joints
#: placed on it as Slicer markups (``ant.mrk.json``) and a gait (``ant.keys``): :mod:`volanim_core.ant_sample`.
#: ``rabbit``, ``spot`` and ``bob`` copy closed meshes other projects ship (trimesh's test rabbit, MIT; Keenan
#: Crane's Spot the cow and Bob, CC0, as geometry-central's test assets): creatures nobody templated.
#: ``fox`` copies Khronos' glTF sample Fox (CC BY 4.0): a real animal's clips (Survey, Walk, Run) in glTF.
#: ``huesitos`` copies assimp's FBX test model of that name (BSD): a branching rig's clip as Blender writes FBX,
#: and a map of it onto the mannequin's spine and arms.
FILE_SAMPLES = ("walk", "mannequin-ct", "ant", "rabbit", "spot", "bob", "cluster", "fox", "huesitos")
CLUSTER_FILES = ("local", "slurm", "pbs", "kubernetes")  # cluster-NAME.yaml: --cluster-config templates
MESH_SAMPLES = ("rabbit", "spot", "bob")
SAMPLE_DATA = Path(__file__).resolve().parent / "sample_data"  # package data: the clip, meshes, cluster files
#: Samples too large for ``samples all`` (minutes and gigabytes to make): asked for by name only.
BY_NAME_ONLY = ("mannequin-full",)

CT_SPACING, CT_ORIGIN = (0.7, 0.7, 2.5), (-56.0, -35.0, -1150.0)  # a CT's voxels (mm), somewhere in a scanner
#: Hounsfield units a CT of the mannequin's tissues would read (air: -1000).
CT_HU = {SKIN: 30, FAT: -100, MUSCLE_A: 45, MUSCLE_B: 60, BONE: 700, SKULL: 900, BRAIN: 35}


@dataclass
class Sample:
    """A demo dataset: volume ``[x, y, z]``, its bone skeleton, and metadata."""

    name: str
    volume: np.ndarray
    bones: BoneSkeleton | None = None
    part: np.ndarray | None = None  # bone index + 1 per voxel, 0 background
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)
    mask_level: int = 1  # the object is volume >= mask_level
    origin: tuple[int, int, int] = (0, 0, 0)  # voxel [0, 0, 0] is this voxel of the rest grid (a posed body)

    @property
    def mask(self) -> np.ndarray:
        from volanim_core.volume import brightest

        return brightest(self.volume) >= self.mask_level


def mannequin_limb(bone_label: str) -> str:
    """The limb a mannequin bone belongs to: TORSO, HEAD, L_ARM, R_ARM, L_LEG or R_LEG.

    Scoring connectivity by limb ignores the arbitrary split of the torso into
    spine, clavicle and pelvis parts and counts what breaks a pose: a point on
    the wrong limb.
    """
    if bone_label == "SPINE" or bone_label.endswith(("CLAVICLE", "PELVIS")):
        return "TORSO"
    if bone_label == "HEAD":
        return "HEAD"
    return bone_label[:2] + ("ARM" if bone_label.endswith(("UPPERARM", "FOREARM", "HAND")) else "LEG")


def mannequin() -> Sample:
    """A procedural humanoid, about 160 x 100 x 300 voxels, with layered interior.

    Skin, fat, striped muscle (stripes across each limb, so they move with it)
    and bone rods inside the limbs; a skull and brain in the head.
    """
    return _mannequin(np.ones(3), "mannequin")


TUBE_RADIUS = 6.0  # the curved tube's radius (voxels)


def curved_tube(radius: float = TUBE_RADIUS, bend: float = 40.0, n_bones: int = 8) -> Sample:
    """A tube bent through half a circle, the thesis's colon case (section 5.3): its centre line runs along
    the arc of radius ``bend`` in the x-z plane, a chain of ``n_bones`` bones (S1 .. Sn) on its chords.
    ``volanim straighten`` lays it straight."""
    pad = int(np.ceil(radius)) + 3
    size = (int(2 * (bend + pad)) + 1, 2 * pad + 1, int(bend + 2 * pad) + 1)
    centre = np.array([bend + pad, pad, pad], np.float64)
    x, y, z = np.meshgrid(*(np.arange(n, dtype=np.float64) for n in size), indexing="ij")
    dx, dy, dz = x - centre[0], y - centre[1], z - centre[2]
    angle = np.arctan2(dz, dx)
    on_arc = (angle >= 0) & (angle <= np.pi)
    ends = [centre + bend * np.array([np.cos(a), 0.0, np.sin(a)]) for a in (0.0, np.pi)]
    to_end = np.minimum(*(np.sqrt((x - e[0]) ** 2 + (y - e[1]) ** 2 + (z - e[2]) ** 2) for e in ends))
    distance = np.where(on_arc, np.sqrt((np.hypot(dx, dz) - bend) ** 2 + dy * dy), to_end)
    volume = np.where(distance <= radius, 200, 0).astype(np.uint8)
    angles = np.linspace(0.0, np.pi, n_bones + 1)
    joints = {f"j{k}": centre + bend * np.array([np.cos(a), 0.0, np.sin(a)]) for k, a in enumerate(angles)}
    bones = BoneSkeleton(joints, [Bone(f"j{k}", f"j{k + 1}", f"S{k + 1}") for k in range(n_bones)])
    return Sample("curved-tube", np.asfortranarray(volume), bones)


def mannequin_large(progress=None) -> Sample:
    """The mannequin at the thesis's half-size Visible Human scale, 290 x 169 x 940 voxels (46 M).

    The same body sampled on a finer grid (1.81 x 1.69 x 3.13 voxels per mannequin
    voxel), not an enlarged copy: surfaces stay smooth and every tissue layer is
    thicker in voxels, as in a higher-resolution scan. Its bones are the
    mannequin's, scaled. ``progress(done, total)`` counts body parts (~2 s in all).
    """
    return _mannequin(np.array(LARGE_SHAPE, float) / MANNEQUIN_SHAPE, "mannequin-large", progress)


def mannequin_full(progress=None) -> Sample:
    """The mannequin on the thesis's full Visible Human grid, 580 x 338 x 1880 voxels (368 M): the body of
    :func:`mannequin_large` sampled twice as finely along each axis, for runs at the thesis's target size
    (`volanim sequence` on a cluster). ``progress(done, total)`` counts body parts."""
    return _mannequin(np.array(FULL_SHAPE, float) / MANNEQUIN_SHAPE, "mannequin-full", progress)


def part_connectivity(sample: Sample, min_thinness: float = 0.5, progress=None):
    """The sample's skeleton (thinness >= ``min_thinness``) with every point attached to the bone
    of the body part it lies in (the ground truth, not a guess): a ready ``.connect``.
    ``progress`` is the skeletonization's."""
    from volanim_core.rig.connectivity import Connectivity
    from volanim_core.rig.pose import root_bones
    from volanim_core.skeleton.skeletonize import skeletonize

    skel = skeletonize(sample.mask, min_thinness=min_thinness, progress=progress)
    x, y, z = skel.points.astype(int).T
    bone = sample.part[x, y, z].astype(int) - 1
    conn = Connectivity(root_bones(sample.bones), skel.points, skel.dt, skel.thinness, bone, skel.metric,
                        thinness_threshold=min_thinness)
    return conn.grouped()


def _mannequin(scale: np.ndarray, name: str, progress=None) -> Sample:
    shape = tuple(int(round(n * f)) for n, f in zip(MANNEQUIN_SHAPE, scale))
    bones = mannequin_bones_at(scale)
    vol, part = paint_mannequin(bones, scale, shape, progress=progress)
    return Sample(name, vol, bones, part)


#: sRGB of each mannequin tissue: skin, fat, two muscle stripes, bone, skull, brain (two stripes).
TISSUE_COLOURS = {SKIN: (222, 170, 140), FAT: (238, 214, 128), MUSCLE_A: (178, 48, 46), MUSCLE_B: (132, 30, 38),
                  BONE: (236, 230, 212), SKULL: (226, 216, 192), BRAIN: (206, 150, 156), BRAIN + 12: (182, 122, 132)}


def mannequin_colour() -> Sample:
    """The mannequin in anatomical colours, ``[x, y, z, 3]`` uint8 RGB (black background).

    Each tissue has its colour, shaded lighter towards the head and with a little
    per-voxel grain, so the volume has thousands of distinct colours, as a
    photographed cryosection does, and a palette has to be built for it.
    """
    grey = mannequin()
    table = np.zeros((256, 3), np.float32)
    for value, colour in TISSUE_COLOURS.items():
        table[value] = colour
    body = grey.volume > 0
    shade = np.linspace(0.88, 1.08, grey.volume.shape[2], dtype=np.float32)
    grain = np.random.default_rng(15).normal(0.0, 4.0, grey.volume.shape + (3,)).astype(np.float32)
    rgb = table[grey.volume] * shade[None, None, :, None] + grain
    rgb = np.where(body[..., None], np.clip(np.rint(rgb), 1, 255), 0).astype(np.uint8)
    return Sample("mannequin-colour", rgb, grey.bones, grey.part)


ALIAS_SIZE, ALIAS_CUBE, ALIAS_BLOCK = 128, 107, 9


def aliascube() -> Sample:
    """The thesis's aliasing test cube: 128^3, a 107^3 checkerboard of 50 and 250.

    Blocks of 9 voxels: the largest block size whose checkerboard gives exactly
    the thesis's Table 5.2 counts (872109 zeros, 612521 of 50, 612522 of 250);
    sizes 1, 2, 3, 6, 9, 18 and 27 all do, and 9 shows clear squares.
    """
    start = (ALIAS_SIZE - ALIAS_CUBE) // 2
    i = np.arange(ALIAS_CUBE) // ALIAS_BLOCK
    parity = (i[:, None, None] + i[None, :, None] + i[None, None, :]) % 2
    vol = np.zeros((ALIAS_SIZE,) * 3, np.uint8, order="F")
    sl = slice(start, start + ALIAS_CUBE)
    vol[sl, sl, sl] = np.where(parity == 0, 250, 50)
    return Sample("aliascube", vol)


def frog() -> Sample:
    """The segmented frog shipped with pyvista (500 x 470 x 136 tissue labels, 1 x 1 x 1.5 mm)."""
    from pyvista import examples  # lazy: VTK only here

    img = examples.load_frog_tissues()
    data = np.asfortranarray(np.asarray(img.point_data.active_scalars).reshape(img.dimensions, order="F"))
    data = data.astype(np.uint8, copy=False)
    head = np.argwhere(np.isin(data, FROG_HEAD_LABELS)).mean(0)
    return Sample("frog", data, bones=principal_axis_bones(data > 0, head=head), spacing=tuple(img.spacing))


#: The frog's tissue labels at its head end: brain, eye retina, eye white (the labels of VTK's
#: Frog examples: 1 blood, 2 brain, 3 duodenum, 4 eye retina, 5 eye white, 6 heart, ...).
FROG_HEAD_LABELS = (2, 4, 5)


def principal_axis_bones(mask: np.ndarray, names=("BODY", "LEGS"), head=None) -> BoneSkeleton:
    """A two-bone chain along the object's principal axis (PCA of its voxels).

    Joints: both ends of the object along the axis (10th and 90th percentiles)
    and the middle. Crude, but it gives any dataset -- like the frog, which
    ships no skeleton -- a bone to pose for benchmarks and the demo. The first
    bone (``names[0]``) runs from the middle to the end nearer ``head`` (when
    given): the sign of a principal axis is arbitrary, so without it the frog's
    BODY pointed at its legs.
    """
    pts = np.argwhere(mask)[:: max(1, int(mask.sum()) // 200000)].astype(np.float64)
    centre = pts.mean(0)
    _, _, vt = np.linalg.svd(pts - centre, full_matrices=False)
    axis = vt[0]
    if head is not None and (np.asarray(head, np.float64) - centre) @ axis > 0:
        axis = -axis  # the low end (A, the first bone's distal joint) is the head's
    t = (pts - centre) @ axis
    lo, hi = np.percentile(t, [10, 90])
    raw = {"A": centre + lo * axis, "MID": centre + 0.5 * (lo + hi) * axis, "B": centre + hi * axis}
    joints = {k: _deepest_near(mask, v) for k, v in raw.items()}
    return BoneSkeleton(joints, [Bone("MID", "A", names[0]), Bone("MID", "B", names[1])])


def _deepest_near(mask: np.ndarray, target, radius: float = 60.0, step: int = 4) -> np.ndarray:
    """The object voxel deepest inside (largest distance to the surface) within ``radius`` of ``target``.

    On a ``step``-times downsampled mask, so it costs milliseconds; keeps joints inside the body.
    """
    from scipy import ndimage

    small = mask[::step, ::step, ::step]
    depth = ndimage.distance_transform_edt(np.pad(small, 1))[1:-1, 1:-1, 1:-1]
    g = np.indices(small.shape).reshape(3, -1).T * step
    near = ((g - np.asarray(target)) ** 2).sum(1) <= radius * radius
    score = np.where(near, depth.ravel(), -1.0)
    if score.max() <= 0:
        return np.round(np.asarray(target, np.float64), 1)
    return g[int(np.argmax(score))].astype(np.float64)


def load(name: str) -> Sample:
    """A demo dataset by name: one of :data:`~volanim_core.samples.NAMES`."""
    makers = {"mannequin": mannequin, "mannequin-colour": mannequin_colour, "mannequin-large": mannequin_large,
              "mannequin-full": mannequin_full,
              "aliascube": aliascube, "frog": frog, "curved-tube": curved_tube}
    if name not in makers:
        raise ValueError(f"unknown sample {name!r}; choose one of {', '.join(NAMES + BY_NAME_ONLY)}")
    return makers[name]()


def _copy_package_data(folder: Path, names: list[str]) -> list[Path]:
    """Files of ``sample_data/`` (package data) copied into ``folder``, each written atomically."""
    from volanim_core.io.atomic import atomic_write_bytes

    written = [folder / n for n in names]
    for dst in written:
        atomic_write_bytes(dst, (SAMPLE_DATA / dst.name).read_bytes())
    return written


def walk_clip() -> Path:
    """The bundled motion-capture walk (``walk.bvh``, package data; its MIT licence is beside it)."""
    return SAMPLE_DATA / "walk.bvh"


def write_mannequin_ct(folder: str | Path, progress=None) -> list[Path]:
    """The mannequin as a CT series arrives: ``mannequin-ct/`` (DICOM, one file a slice, Hounsfield
    units stored with intercept -1024, 0.7 x 0.7 x 2.5 mm voxels at :data:`CT_ORIGIN`) and
    ``mannequin-ct.bones``: its bones in the voxels of the 0.7 mm cubes ``skeletonize`` makes of it.

    The body is the mannequin's voxels taken as 1 mm cubes, sampled (nearest) onto the CT's grid.
    """
    from volanim_core.geometry import Geometry
    from volanim_core.io import write_bones
    from volanim_core.io.dicom_files import write_dicom_series
    from volanim_core.volume import resample

    folder = Path(folder)
    s = mannequin()
    table = np.full(256, -1000, np.int16)
    for value, hu in CT_HU.items():
        table[value] = hu
    hu = table[s.volume]
    ct, geometry = resample(hu, Geometry(origin=CT_ORIGIN), CT_SPACING, order=0, progress=stage(progress, 0, 30))
    write_dicom_series(folder / "mannequin-ct", ct, geometry, description="mannequin CT (volanim sample)")
    cube = CT_SPACING[0]  # skeletonize's default voxel: the smallest spacing
    cubes = geometry.with_spacing((cube,) * 3)  # the grid skeletonize makes: the bones record it
    bones = BoneSkeleton({n: np.round(np.asarray(p) / cube, 3) for n, p in s.bones.joints.items()}, list(s.bones.bones),
                         cubes)
    write_bones(folder / "mannequin-ct.bones", bones)
    if progress is not None:
        progress(1, 1)
    return [folder / "mannequin-ct", folder / "mannequin-ct.bones"]


def write_mannequin_keys(path: str | Path, bones: BoneSkeleton) -> None:
    """A one-second wave of the mannequin's left arm as a ``.keys`` file (docs/formats.md, "Keys")."""
    from volanim_core.io.keys_files import Keys, write_keys
    from volanim_core.rig.key_pose import KeyPose

    def key(**angles) -> KeyPose:
        k = KeyPose()
        for label, a in angles.items():
            b = bones.bones[bones.index(label)]
            k.angles[(b.proximal, b.distal)], k.shifts[(b.proximal, b.distal)] = np.array(a, float), np.zeros(3)
        return k

    write_keys(path, Keys({0: key(), 12: key(L_UPPERARM=(0, -80, 0), L_FOREARM=(0, -40, 0), SPINE=(0, 0, 8)),
                           24: key()}, fps=24.0, length=25, ease=True), bones)


def write_sample(name: str, folder: str | Path, progress=None) -> list[Path]:
    """Write a sample's files into ``folder``: ``NAME.VOL`` (+ ``.bones``/``.connections``), or for
    ``walk`` the clip ``walk.bvh`` and its licence. ``progress(done, total)`` is reported for
    ``mannequin-large`` (its body, then the skeleton of its ``.connect``: ~10 s on 2 cores)."""
    from volanim_core.io import write_bones, write_connections, write_raw
    from volanim_core.io.atomic import atomic_write_bytes

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    if name == "mannequin-ct":
        return write_mannequin_ct(folder, progress)
    if name == "ant":
        from pyvista import examples  # lazy: VTK only here

        from volanim_core.ant_sample import write_ant_rig

        written = [folder / "ant.ply"]
        atomic_write_bytes(written[0], Path(examples.antfile).read_bytes())
        return written + write_ant_rig(folder)  # its joints as Slicer markups, and a gait
    if name in MESH_SAMPLES:
        return _copy_package_data(folder, [f"{name}.ply", f"{name}.ply.LICENSE"])
    if name == "cluster":  # files to start a Dask cluster from (--cluster-config), to edit (docs: cluster.md)
        return _copy_package_data(folder, [f"cluster-{kind}.yaml" for kind in CLUSTER_FILES])
    if name == "walk":
        return _copy_package_data(folder, [walk_clip().name, f"{walk_clip().name}.LICENSE"])
    if name == "fox":
        return _copy_package_data(folder, ["Fox.glb", "Fox.glb.LICENSE"])
    if name == "huesitos":
        return _copy_package_data(folder, ["huesitos.fbx", "huesitos.fbx.LICENSE", "huesitos.mannequin.map"])
    # the large mannequins: the body is the first 20 %, its .connect's skeleton the rest
    big = {"mannequin-large": mannequin_large, "mannequin-full": mannequin_full}
    sample = big[name](stage(progress, 0, 20)) if name in big else load(name)
    written = [folder / f"{name}.VOL"]
    write_raw(written[0], sample.volume)
    if sample.bones is not None:
        written += [folder / f"{name}.bones", folder / f"{name}.connections"]
        write_bones(written[1], sample.bones)
        write_connections(written[2], sample.bones)
    if name == "mannequin":  # keyframes for `volanim keys`: the left arm waves once, the spine leans
        written.append(folder / f"{name}.keys")
        write_mannequin_keys(written[-1], sample.bones)
    if name in big:  # ready to reconstruct at the thesis's scale: its Table 2.2 skeleton
        from volanim_core.io import write_connect

        written.append(folder / f"{name}.connect")
        write_connect(written[-1], part_connectivity(sample, progress=stage(progress, 20, 100)))
    return written
