"""Table 3.1 again: where a reconstruction's time goes, function by function, "% of total time".

The thesis profiled its reconstruction of a posed frame. This runs ``volanim reconstruct`` on a posed
frame of mannequin-large (the thesis's scale; L_UPPERARM turned 45 degrees, sampled mode, from the files
a user has) under cProfile, after one warm call (numba's compiled kernels loaded), and prints each
function's own time (not its callees') as a share of the whole. A numba kernel is one entry: cProfile
sees the call, not what runs inside it.

Instruction counts: ``perf stat -e instructions`` where the machine exposes the CPU's counters; on a
virtual machine without them (this one: "<not supported>") the table says so instead of guessing.

Run: .venv/bin/python benchmarks/profile_table.py [--top N]
"""

from __future__ import annotations

import cProfile
import io as text_io
import pstats
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402


def frame_files(folder: Path) -> tuple[Path, Path]:
    """mannequin-large's posed frame as files: the sample's volume and its .connect, an arm turned."""
    from volanim_core import io, samples
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.pose import pose_matrices, root_bones
    from volanim_core.rig.tskel_tools import connect_to_tskel

    written = samples.write_sample("mannequin-large", folder)
    conn = io.read_connect(next(p for p in written if p.suffix == ".connect"))
    bones = samples.load("mannequin-large").bones
    trans = Trans(root_bones(bones), pose_matrices(bones, {"L_UPPERARM": (0, -45, 0)}))
    io.write_tskel(folder / "arm.tskel", connect_to_tskel(conn, trans))
    return folder / "arm.tskel", folder / "mannequin-large.VOL"


def instructions(command: list[str]) -> str:
    """``perf stat``'s instruction count of ``command``, or why there is none."""
    try:
        out = subprocess.run(["perf", "stat", "-x,", "-e", "instructions", *command], capture_output=True,
                             text=True, check=False)
    except FileNotFoundError:
        return "perf is not installed"
    for line in out.stderr.splitlines():
        if line.endswith("instructions") or ",instructions" in line:
            value = line.split(",")[0]
            return f"{int(value):,} instructions" if value.isdigit() else f"perf: {value} (no CPU counters here)"
    return "perf printed no instruction count"


def main() -> None:
    from volanim_core.cli import main as volanim

    top = int(sys.argv[sys.argv.index("--top") + 1]) if "--top" in sys.argv else 15
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        tskel, source = frame_files(folder)
        args = ["reconstruct", str(tskel), "--mode", "sampled", "--source", str(source), "-o", str(folder / "o.nrrd")]
        volanim(args)  # warm: the kernels compiled or loaded, the files in the page cache
        profile = cProfile.Profile()
        profile.enable()
        volanim(args)
        profile.disable()
        stats = pstats.Stats(profile, stream=text_io.StringIO())
        total = stats.total_tt
        rows = []
        for (path, _line, name), (_, calls, own, _, _) in sorted(stats.stats.items(), key=lambda kv: -kv[1][2])[:top]:
            where = Path(path).name if path != "~" else "builtin"
            rows.append([f"{where}:{name}" if where != "builtin" else name, calls, f"{own:.3f}",
                         f"{100 * own / total:.1f}"])
        count = instructions([sys.executable, "-m", "volanim_core", *args])
    print(f"\nTable 3.1: volanim reconstruct, mannequin-large posed (sampled), {total:.2f} s under cProfile")
    print(table(rows, ["function (own time)", "calls", "s", "% of total time"]))
    print(f"instructions of the whole command: {count}")


if __name__ == "__main__":
    main()
