"""Readers and writers for every file of docs/formats.md.

All readers raise :class:`volanim_core.errors.FormatError` (and nothing else)
for a bad file; all writers are atomic.

    volumes
      volume_files.py ..... every volume format behind read_scan/read_volume and write_volume
      raw_volumes.py ...... .vol and .VOL (the thesis's raw voxels, 100-byte header)
      nrrd_files.py, metaimage_files.py  NRRD and MetaImage, our own; medical_files.py: NIfTI and the
                            others through SimpleITK/nibabel; dicom_files.py: DICOM through pydicom
      vtk_headers.py ...... what a VTK-family header claims, checked before VTK allocates it
    skeletons and the rig
      skeleton_files.py ... .skel and .mskel
      bones_files.py ...... .bones and .connections
      connect_files.py .... .connect, .trans and .tskel (and the smooth-joints line)
      ownership_files.py .. NAME.owners.nrrd beside a .connect: the rig's ownership as a label NRRD
    motion
      frame_files.py ...... an animation on disk: one .trans (and .tskel) per frame, NAME.0000.trans
      keys_files.py ....... .keys (keyframes)
      bvh_files.py ........ BVH clips read (the clip's own hierarchy and forward kinematics); bvh_export.py: written
      gltf_files.py ....... glTF 2.0 clips (.glb .gltf .vrma): a skeleton and one animation, read as a BVH Motion
      gltf_meshes.py ...... a glTF file's surface at rest (skins applied), a mesh to voxelize
      fbx_files.py ........ FBX clips through assimp (impasse), read as a Motion by the glTF rules
      gltf_export.py ...... an animated, skinned .glb written from arrays (what: render/skinned_body.py)
      clip_bake.py ........ what the glTF and FBX readers share: key sampling, frame times, world matrices -> Motion
      clip_files.py ....... a clip read by its kind (BVH, glTF, FBX): what every command and the studio call
      mapping_files.py .... BONE BVH_JOINT mapping files
      positions_files.py .. joint positions per frame (CSV)
      marker_files.py ..... C3D marker data and marker maps; c3d_layout.py: a C3D file checked before ezc3d
    rendering, colour, meshes, other programs
      render_files.py ..... the Rendering section's files: .camera and .tf
      palette_files.py .... palettes, alpha maps, remap tables
      mesh_files.py ....... surfaces in and out (.ply .vtp .obj .stl; .glb .gltf in); mesh_checks.py: meshes
                            checked before VTK reads them
      slicer_files.py ..... 3D Slicer's markups and transform files
      bundle.py ........... several files saved as one unit (a project): data files, then the manifest
    what every reader and writer shares
      atomic.py ........... atomic writes (a temporary beside the target, then a rename)
      text.py ............. the line reader of every text format; files.py: a named file read safely
      _columns.py, _inflate.py  numeric columns parsed fast; gzip inflated with a cap (io's own)
"""

from volanim_core.errors import FormatError

from .bones_files import read_bones, read_connections, write_bones, write_connections
from .connect_files import (
    connect_filename,
    read_connect,
    read_trans,
    read_tskel,
    write_connect,
    write_trans,
    write_tskel,
)
from .raw_volumes import (
    add_header,
    dims_from_name,
    histogram_file,
    raw_name_for,
    read_raw,
    remove_header,
    write_raw,
)
from .render_files import read_camera, read_transfer_function, write_camera, write_transfer_function
from .skeleton_files import read_mskel, read_skel, read_skeleton, skeleton_at, write_mskel, write_skel, write_skeleton
from .volume_files import (
    Scan,
    read_image_folder,
    read_scan,
    read_volume,
    saturate_for_raw,
    write_output,
    write_volume,
)

__all__ = [
    "read_camera",
    "read_transfer_function",
    "write_camera",
    "write_transfer_function",
    "FormatError",
    "add_header",
    "connect_filename",
    "dims_from_name",
    "raw_name_for",
    "histogram_file",
    "read_bones",
    "read_connect",
    "read_connections",
    "read_image_folder",
    "read_mskel",
    "read_raw",
    "read_skel",
    "read_skeleton",
    "skeleton_at",
    "read_trans",
    "read_tskel",
    "read_volume",
    "read_scan",
    "Scan",
    "remove_header",
    "saturate_for_raw",
    "write_output",
    "write_bones",
    "write_connect",
    "write_connections",
    "write_mskel",
    "write_skeleton",
    "write_raw",
    "write_skel",
    "write_trans",
    "write_tskel",
    "write_volume",
]
