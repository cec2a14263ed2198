"""Atomic file writes: write a temporary file beside the target, then rename.

A crash (or an exception while formatting) leaves the previous file intact,
never a half-written one. ``os.replace`` is atomic on POSIX and Windows when
source and target are on the same file system, hence the temporary file lives
in the target's folder.

Temporary names carry the writer's process id (``.NAME.<pid>-<random>.tmp``).
A kill -9 cannot clean up after itself, so every write first removes the
temporaries in the same folder whose process is gone (``clean_stale``).
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import shutil
import time
from pathlib import Path

LEGACY_STALE_SECONDS = 600  # temporaries without a pid (older versions) are stale after this


def free_bytes(path) -> int | None:
    """Bytes a user may still write on the device that holds ``path`` (its nearest existing folder); None
    when that cannot be read."""
    folder = Path(path)
    while not folder.is_dir() and folder != folder.parent:
        folder = folder.parent
    try:
        room = os.statvfs(folder)
    except OSError:
        return None
    return room.f_bavail * room.f_frsize


def out_of_room(exc: BaseException, path, what: str, needs=None) -> OSError | None:
    """The full disk ``exc`` (ENOSPC, no file named) said of ``path``, the file being written: the CLI names
    an OSError's file, and named the *input* it was reading when none was given. None for anything else.

    The message says how much room the write needs and how much is free (#89: "it needs more" left the user
    guessing how much to clear). ``needs``: bytes (an int), a phrase ("up to 1,234 bytes"), or a callable
    giving either, asked only when the disk filled (what is left to write is known only then)."""
    if isinstance(exc, OSError) and exc.errno == errno.ENOSPC and exc.filename is None:
        needs = needs() if callable(needs) else needs
        need = f"{needs:,} bytes" if isinstance(needs, int) else (needs or "more room than there is")
        free = free_bytes(path)
        room = "the free room could not be read" if free is None else f"{free:,} bytes are free there"
        return OSError(errno.ENOSPC, f"no space left on the device for {what}; it needs {need}, {room}", str(path))
    return None


class naming_the_output:  # noqa: N801 - used as a context manager, named as one
    """``with naming_the_output(path, what, needs):`` re-raises a full disk met inside as :func:`out_of_room` of
    ``path``. Reusable: one object may guard several blocks writing the same output."""

    def __init__(self, path, what: str, needs=None):
        self.path, self.what, self.needs = path, what, needs

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        full = out_of_room(exc, self.path, self.what, self.needs) if exc is not None else None
        if full is not None:
            raise full from exc
        return False


def pending_name(name: str, suffix: str = ".tmp") -> str:
    """A hidden temporary name for ``name`` in the same folder, owned by this process."""
    return f".{name}.{os.getpid()}-{secrets.token_hex(4)}{suffix}"  # matches _OURS


def _pid_alive(pid: int, since: float | None = None) -> bool:
    """Whether process ``pid`` lives and, given ``since`` (a temporary's mtime), is the one that wrote it:
    pids are reused (a container's run through the same few thousand), and a process that started after
    the file was last written cannot be its writer (Linux: its start time from /proc)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    started = _start_time(pid)
    return since is None or started is None or started <= since + 1.0


def _start_time(pid: int) -> float | None:
    """When process ``pid`` started (seconds since the epoch), or None where /proc does not say."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        ticks = int(fields[19])  # field 22 of stat: starttime, clock ticks after boot
        boot = next(float(line.split()[1]) for line in Path("/proc/stat").read_text().splitlines()
                    if line.startswith("btime "))
        return boot + ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, StopIteration):
        return None


_OURS = re.compile(r"^\..+\.(\d+)-[0-9a-f]{8}\.tmp(?:\.[A-Za-z0-9]+)?$")  # pending_name's shape


def clean_stale(folder: Path, name: str | None = None, suffix: str = ".tmp") -> int:
    """Remove temporaries that writers which died left in ``folder``; returns how many.

    Every temporary of ours names its process, so any of them whose process is
    gone is stale, whatever it was for (a kill can leave nested ones). Older
    versions' temporaries of ``name`` (no pid) are stale after ten minutes.
    """
    legacy = None
    if name is not None:
        legacy = re.compile(r"^\." + re.escape(name) + r"(?:\.[A-Za-z0-9_]{8})?" + re.escape(suffix) + "$")
    removed = 0
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return 0
    for entry in entries:
        try:
            ours = _OURS.match(entry.name)
            if ours:
                stale = not _pid_alive(int(ours.group(1)), entry.stat(follow_symlinks=False).st_mtime)
            elif legacy is not None and legacy.match(entry.name):
                stale = time.time() - entry.stat().st_mtime > LEGACY_STALE_SECONDS
            else:
                continue
            if stale and entry.is_file(follow_symlinks=False):
                os.unlink(entry.path)
                removed += 1
            elif stale and ours and entry.is_dir(follow_symlinks=False):  # a store made beside its target
                shutil.rmtree(entry.path, ignore_errors=True)
                removed += 1
        except (OSError, ValueError):
            continue
    return removed


def fsync_folder(folder: str | Path) -> None:
    """Make renames inside ``folder`` durable (POSIX; a no-op where folders cannot be opened)."""
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _read_umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


_UMASK = _read_umask()  # read once: os.umask is process-wide, changing it per write races other threads


@contextlib.contextmanager
def atomic_open(path: str | Path, mode: str = "w", *, size: int | None = None, **kwargs):
    """Open a temporary file for writing; on success rename it to ``path``. ``size``: the bytes the file
    will take, when the writer knows (a full disk's message says it)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    clean_stale(path.parent, path.name)
    tmp = path.parent / pending_name(path.name)
    # the mode a plain open() would give (or the mode of the file being replaced)
    file_mode = path.stat().st_mode & 0o7777 if path.exists() else 0o666 & ~_UMASK
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        os.chmod(tmp, file_mode)
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        written = tmp.stat().st_size if tmp.exists() else 0
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        needs = size if size is not None else f"more than {written:,} bytes (that much was written when it filled)"
        full = out_of_room(exc, path, "it", needs)
        if full is not None:
            raise full from exc
        raise


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically (UTF-8, ``\\n`` line ends)."""
    data = text.encode("utf-8")  # its size known before writing: a full disk's message says it
    with atomic_open(path, "wb", size=len(data)) as fh:
        fh.write(data)


def atomic_write_bytes(path: str | Path, data: bytes | memoryview) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_open(path, "wb", size=memoryview(data).nbytes) as fh:
        fh.write(data)


def atomic_vtk_save(path: str | Path, dataset) -> None:
    """Save a pyvista dataset atomically: VTK writes by file name, so write a
    temporary name beside the target (same suffix, so VTK picks the writer), then rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    clean_stale(path.parent, path.stem, f".tmp{path.suffix}")
    tmp = path.parent / pending_name(path.stem, f".tmp{path.suffix}")
    _check_room(path, dataset)
    try:
        dataset.save(str(tmp))
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        _check_vtk_file(tmp, path, dataset)  # VTK reports a full disk on its error output and returns
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


_XML_SUFFIXES = (".vti", ".vtp", ".vtu", ".vts", ".vtr")


def _check_room(path: Path, dataset) -> None:
    """Refuse (OSError ENOSPC) before VTK writes into too little room: its XML PolyData writer aborts the
    process on a full disk (free(): invalid pointer). The most a file can take: 1.5x the data in XML
    (base64), 3x in the text and list formats (.obj, .ply, .stl), plus 1 MB."""
    import errno

    room = os.statvfs(path.parent)
    free = min(room.f_bavail, room.f_bfree) * room.f_frsize
    need = int(dataset.actual_memory_size * 1024 * (1.5 if path.suffix.lower() in _XML_SUFFIXES else 3)) + (1 << 20)
    if free < need:
        raise OSError(errno.ENOSPC, f"not enough room to write {path}: it needs up to {need:,} bytes, {free:,} "
                                    "bytes are free there; the file that was there is unchanged")


def _check_vtk_file(tmp: Path, path: Path, dataset) -> None:
    """Refuse (OSError) a file VTK did not finish: an XML file without its closing tag, any other that
    reads back with fewer points or cells, or any written while the disk ran out (VTK's PLY reader reads
    a cut binary file back whole, padded with garbage). ``convert`` over an existing .vti replaced it
    with a 16 KB fragment of the new one on a full disk: VTK's writer failed without raising."""
    import errno

    room = os.statvfs(tmp.parent)
    if room.f_bavail == 0 or room.f_bfree == 0:
        complete = False
    elif path.suffix.lower() in _XML_SUFFIXES:
        with open(tmp, "rb") as fh:
            fh.seek(max(0, os.fstat(fh.fileno()).st_size - 64))
            complete = fh.read().rstrip().endswith(b"</VTKFile>")
    else:
        import pyvista as pv

        try:
            back = pv.read(str(tmp))
            complete = (back.n_points, back.n_cells) == (dataset.n_points, dataset.n_cells)
        except Exception:  # noqa: BLE001 - VTK's readers raise many types; any of them means not written
            complete = False
    if not complete:
        free = free_bytes(tmp.parent)
        raise OSError(errno.ENOSPC, f"VTK could not finish writing {path} (is the disk full? it needs about "
                                    f"{dataset.actual_memory_size * 1024:,} bytes, "
                                    f"{'an unknown number of' if free is None else f'{free:,}'} bytes are free "
                                    "there); the file that was there is unchanged")
