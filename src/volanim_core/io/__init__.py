"""Readers and writers for every file of docs/formats.md.

All readers raise :class:`volanim_core.errors.FormatError` (and nothing else)
for a bad file; all writers are atomic.
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
