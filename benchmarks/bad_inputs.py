"""Every bad input of issue 16 (motion files, video, command line) and what ``c2n`` says.

Run ``python benchmarks/bad_inputs.py``: each case is built from the shared
fixtures in a temporary folder and run through the command line in-process;
printed are the exit status and the first line on stderr (or the summary
line for inputs that are read), and whether an output folder was left
behind.  Run it on another checkout with ``PYTHONPATH`` to see the before.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from click.testing import CliRunner

FIXTURES = Path(__file__).resolve().parents[1].parent / "shared" / "fixtures"
MOCAP = FIXTURES / "bvh" / "test_mocapbank.bvh"
KINECT = FIXTURES / "kinect" / "joints.csv"


def _bvh(work: Path, name: str, old: str, new: str) -> Path:
    path = work / f"{name}.bvh"
    path.write_text(MOCAP.read_text().replace(old, new, 1))
    return path


def _nan3(work: Path) -> Path:
    lines = MOCAP.read_text().splitlines()
    m = lines.index("MOTION")
    for k, col, value in ((0, 5, "nan"), (0, 10, "inf"), (47, 7, "-inf")):
        row = lines[m + 3 + k].split()
        row[col] = value
        lines[m + 3 + k] = " ".join(row)
    path = work / "nan3.bvh"
    path.write_text("\n".join(lines) + "\n")
    return path


def _kinect(work: Path, name: str, row: int, value: str) -> Path:
    lines = KINECT.read_text().splitlines()
    cells = lines[row].split(",")
    cells[0] = value
    lines[row] = ",".join(cells)
    path = work / f"{name}.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def cases(work: Path) -> list[tuple[str, list]]:
    afile = work / "afile"
    afile.write_text("x")
    empty = work / "empty.lab"
    empty.write_text("title: nothing\ntempo: 60\nmeter: 4\n")
    lab = work / "phrase.lab"
    lab.write_text("tempo: 60\n0 1 right_arm forward middle\n1 1 right_arm right high\n")
    out = str(work / "out")
    bvh = [
        ("BVH with 3 NaN/inf values", _nan3(work)),
        ("BVH Frames: 0", _bvh(work, "f0", "Frames:\t455", "Frames:\t0")),
        ("BVH Frames: inf", _bvh(work, "finf", "Frames:\t455", "Frames:\tinf")),
        ("BVH Frames: nan", _bvh(work, "fnan", "Frames:\t455", "Frames:\tnan")),
        ("BVH Frames: -1e308", _bvh(work, "f308", "Frames:\t455", "Frames:\t-1e308")),
        ("BVH Frames: -1", _bvh(work, "fm1", "Frames:\t455", "Frames:\t-1")),
        ("BVH Frames: 2.7", _bvh(work, "f27", "Frames:\t455", "Frames:\t2.7")),
        ("BVH CHANNELS nan", _bvh(work, "chnan", "CHANNELS 3 Zrotation", "CHANNELS nan Zrotation")),
        ("BVH Frame Time: 1e-300", _bvh(work, "ft", "Frame Time:\t0.033333", "Frame Time:\t1e-300")),
        ("BVH OFFSET nan", _bvh(work, "offnan", "OFFSET -0.1728 10.2870", "OFFSET nan 10.2870")),
        ("Kinect CSV NaN timestamp", _kinect(work, "knan", 5, "nan")),
        ("Kinect CSV timestamp 10^15", _kinect(work, "kbig", 5, "1000000000000000")),
        ("Kinect CSV last timestamp 10^15", _kinect(work, "klast", -1, "1000000000000000")),
    ]
    out_cases = [(name, ["capture", str(p), "-o", out, "--no-effort"]) for name, p in bvh]
    out_cases += [
        ("--tempo nan", ["capture", str(MOCAP), "-o", out, "--tempo", "nan"]),
        ("--tempo inf", ["capture", str(MOCAP), "-o", out, "--tempo", "inf"]),
        ("-o below a regular file", ["capture", str(MOCAP), "-o", str(afile / "sub"), "--no-effort"]),
        ("-o in a read-only folder (/sys)", ["capture", str(MOCAP), "-o", "/sys/c2n-out", "--no-effort"]),
        ("--timing-tolerance nan", ["score", str(lab), str(lab), "-o", out, "--timing-tolerance", "nan"]),
        ("empty candidate score", ["score", str(empty), str(lab), "-o", out]),
        ("unknown file kind (score)", ["score", str(afile), str(lab), "-o", out]),
    ]
    return out_cases


def main() -> None:
    from pipelines.cli import main as c2n

    work = Path(tempfile.mkdtemp(prefix="bad_inputs_"))
    for name, args in cases(work):
        r = CliRunner().invoke(c2n, args)
        err = [ln for ln in (r.stderr or "").splitlines() if ln.strip()]
        if r.exception is not None and not isinstance(r.exception, SystemExit):
            first = f"{type(r.exception).__name__}: {r.exception}"[:160]
        elif r.exit_code == 0:
            first = (r.stdout.splitlines() or [""])[0]
            if err:
                first = f"{err[0]}  ||  {first}"
        else:
            first = err[0] if err else r.stdout.strip()[:160]
        left = r.exit_code != 0 and (work / "out").exists()
        print(
            f"{name:<34} exit {r.exit_code}  {first.replace(str(work) + '/', '')}{'  [left out/ behind]' if left else ''}"
        )
        if (work / "out").exists():
            import shutil

            shutil.rmtree(work / "out")


if __name__ == "__main__":
    main()
